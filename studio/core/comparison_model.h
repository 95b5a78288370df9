// The images of every view and what they are compared against: each view's latest image and reference with the
// state of the scene they render, the pair of one state its comparisons use, the metrics of that pair (whole and over
// the user's region), the convergence points of progressive renders, and the user's choice of comparand (the
// reference, a snapshot, or another view's image, Shift+1-9). It takes the render scheduler's outputs and is read by
// the compositor, the docks, the plots and the exporter; a comparison is made only between images of one state
// (compositor.h, ComparisonPair). Metrics and relMSE are computed in the background pool; a result is kept only if
// its view still shows the same two images.
#pragma once

#include "background.h"
#include "compositor.h"
#include "render_service.h"

#include <QObject>
#include <QRect>

#include <atomic>
#include <functional>
#include <memory>
#include <vector>

namespace tyndall::studio {

// One point of a view's convergence: its error against the reference when it had `spp` samples.
struct ConvergencePoint {
    int spp = 0;
    double seconds = 0.0;
    double relMSE = 0.0;
};

class ComparisonModel : public QObject {
    Q_OBJECT
public:
    ComparisonModel(Background& background, QObject* parent = nullptr);
    // Waits for its jobs on the shared background pool: each ends by posting its result to this model, which must
    // still exist when it posts (a queued call to an object deleted after the post is dropped).
    ~ComparisonModel() override;

    // A view list of its own: names, display names of techniques, exposures and the states of their parts.
    struct ViewInfo {
        QString name, technique;
        double exposure = 0.0;
        quint64 state = 0;
    };
    // The project's views (index 0 .. n-1) start again; the images opened from files stay, after them.
    void reset(const std::vector<ViewInfo>& views);
    // The project's views after an authoring: view i was view oldOf[i] before (-1: new), and keeps its images,
    // references, metrics, convergence points and the user's choices that name it; the images opened from files stay.
    void followViews(const std::vector<ViewInfo>& views, const std::vector<int>& oldOf);
    const std::vector<ViewFrame>& frames() const { return frames_; }
    int size() const { return int(frames_.size()); }

    // Images opened from files (image_file.h) as read-only views after the project's: each is compared against the
    // reference of a project view (`against`; the first by default), and can be chosen as every view's comparand
    // (Shift+N) like any view. Returns the new view's index.
    int addImage(const QString& name, const QString& kind, std::shared_ptr<const Image> image, int against = 0);
    bool isImage(int view) const { return view >= projectViews_ && view < size(); }
    int projectViews() const { return projectViews_; }
    // The project view whose reference image view `view` is compared against; -1 for a project view.
    int imageAgainst(int view) const;
    void setImageAgainst(int view, int against);
    void renameImage(int view, const QString& name);
    void removeImage(int view);

    // The state of a view's part changed (an edit): its images become stale until new ones arrive.
    void setState(int view, quint64 state);
    void setExposure(int view, double exposure);  // PSNR depends on it: the metrics follow
    void setTechniqueLabel(int view, const QString& label);  // its parameters changed what the view is
    // The scheduler's news: a render started (targetSpp: a reference's), failed before it started, or sent an image.
    void renderStarted(int view, bool reference, int targetSpp);
    void renderFailed(int view, const QString& error);
    void renderStopped(int view, bool reference);  // cancelled, nothing on its way (the reference while playing)
    void addOutput(const RenderOutput& out);

    void setRegion(QRect region);  // image pixels; empty: none
    QRect region() const { return region_; }
    // Compares view `view` against `image` (a snapshot named `name`) instead of its reference; view -1: off.
    void compareWithSnapshot(int view, std::shared_ptr<const Image> image, const QString& name);
    // Every other view is compared against view `view`'s image (Shift+1-9); -1: the reference again.
    void chooseReferenceView(int view);
    int referenceView() const { return referenceView_; }

    // The convergence plot keeps one point per bucket of spp, four buckets per octave (the newest image of each).
    static int convergenceBucket(int spp);
    // The relMSE over spp and seconds of each view's progressive images against its comparand.
    void convergenceSeries(std::vector<QString>& names, std::vector<std::vector<ConvergencePoint>>& points) const;
    // No metrics, FLIP or relMSE job is in flight.
    bool idle() const { return metricsPending_ == 0 && flipPending_ == 0 && convergencePending_ == 0; }

signals:
    void framesChanged();       // anything the viewport shows
    void metricsChanged();      // the metrics dock's numbers
    void convergenceChanged();  // the convergence plot's points

private:
    void updateMetrics(int view);
    // HDR-FLIP of the view's pair: the region's mean from the stored map when the pair is the same, else a job in the
    // background unless one runs for the view (then one more for the newest pair when it ends) or anything renders.
    void updateFlip(int view);
    bool anyRendering() const;                 // a view's or a reference's render is queued or running
    void flipWhenIdle();                       // once nothing renders: FLIP of every view whose pair has none yet
    int viewOfMetrics(quint64 request) const;  // the view whose latest metrics job it is; -1: none
    int viewOfFlip(quint64 request) const;     // the view whose FLIP job it is; -1: none
    void updateConvergence();
    void refreshAlternates();
    void syncImages();  // the image views' references, states and pairs from their project views
    // background_.run, counted in jobsInFlight_ until the job has posted its result.
    void runInBackground(std::function<void()> work);
    std::atomic<int> jobsInFlight_{0};

    struct ImageView {
        QString name, kind;
        std::shared_ptr<const Image> image;
        int against = 0;
    };
    std::vector<ImageView> images_;
    int projectViews_ = 0;

    Background& background_;
    std::vector<ViewFrame> frames_;
    QRect region_;
    int referenceView_ = -1;
    // The images of each view's current render as it refined, for the convergence plot.
    struct Progress {
        int spp = 0;
        double seconds = 0.0;
        std::shared_ptr<const Image> image;
        double relMSE = -1.0;                    // against `against` (-1: not yet); plotted until a newer one arrives
        std::shared_ptr<const Image> against;    // the image relMSE was computed against
        std::shared_ptr<const Image> requested;  // that of the job in flight for it, if any
        quint64 state = 0;                       // of the image: compared only with a reference of this state
        bool againstAlternate = false;           // `against` is the image of the view chosen with Shift+1-9
    };
    std::vector<std::vector<Progress>> progress_;
    int metricsPending_ = 0, flipPending_ = 0, convergencePending_ = 0;
    quint64 metricsRequests_ = 0;  // metrics and FLIP jobs started so far
    struct ViewJobs {
        quint64 metrics = 0;  // the metrics job whose result the view shows (an older job's is dropped)
        quint64 flip = 0;     // the FLIP job in flight for the view (0: none)
    };
    std::vector<ViewJobs> jobs_;  // per view
};

// Adds a view's progressive image (anything with an `spp`) to its convergence points: a lower spp than the last
// starts a new render's list; an image in the same bucket of spp as the last replaces it. Each point keeps its image,
// to compute its relMSE again as the reference refines, and a progressive technique sends an image per sample (the
// path tracer as a view): this keeps 20 images up to 64 spp and 36 up to 1024, instead of one per spp (the latency
// bench's process grew by ~16 MB/s while its references refined).
template <typename Point>
void addConvergencePoint(std::vector<Point>& points, Point point) {
    if (!points.empty() && points.back().spp >= point.spp) points.clear();
    if (!points.empty() &&
        ComparisonModel::convergenceBucket(points.back().spp) == ComparisonModel::convergenceBucket(point.spp))
        points.pop_back();
    points.push_back(std::move(point));
}

}  // namespace tyndall::studio
