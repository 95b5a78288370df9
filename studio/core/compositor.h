// What the viewport shows, composed on the CPU into one 8-bit sRGB frame at the viewport's size: the views side by
// side (grid), one view (single), or one view wiped against its reference (split); optionally each view's difference
// from its reference on one fixed scale shared by every view, with a colour bar; labels with technique, frame time,
// spp and error metrics. Pure functions of their inputs, so that tests can check what a frame shows.
#pragma once

#include "tyndall/image/colour_management.h"
#include "tyndall/image/image.h"
#include "tyndall/image/metrics.h"

#include <QFont>
#include <QImage>
#include <QStringList>
#include <QRect>
#include <QString>

#include <memory>
#include <optional>
#include <vector>

namespace tyndall::studio {

enum class Layout { Grid, Single, Split };
// Differences against each view's comparand: signed, absolute and relative error on one shared scale, or HDR-FLIP's
// perceptual error map (flip.h, through magma; computed with the frame in the composer's thread, never the GUI's).
enum class DiffMode { Off, Signed, Absolute, Relative, Flip };

struct ViewFrame {
    QString name;
    QString technique;                        // display name
    std::shared_ptr<const Image> image;       // the technique's latest image (null: not rendered yet)
    std::shared_ptr<const Image> reference;   // the reference of the view's part (null: not rendered yet)
    // Staleness: `state` identifies the current state of the view's part of the scene (RenderScheduler hashes it); the image
    // and the reference carry the state they render. A comparison against the reference is made only between an image
    // and a reference of one state: the newest such pair, which is the current one or, after an edit of the part, the
    // last one that matched (stale) until the new reference arrives.
    quint64 state = 0, imageState = 0, referenceState = 0;
    std::shared_ptr<const Image> pairImage, pairReference;
    bool referenceRendering = false;          // a reference render of the view is queued or running
    int referenceTargetSpp = 0;               // what that render goes to
    double referenceEta = -1.0;               // its estimated seconds left (-1: not known yet)
    bool metricsStale = false;                // `metrics` are of a stale pair
    int spp = 0, referenceSpp = 0;
    bool referenceCached = false;             // the reference came from the disk cache
    double seconds = 0.0;                     // the technique's frame time
    double exposure = 0.0;                    // the view's, EV
    bool rendering = false;                   // a newer render is on its way
    // The progressive resolution's latest reduced image (RenderScheduler, resolution_schedule.h): shown scaled up in
    // place of `image` until the next full image arrives, labelled, and never compared.
    std::shared_ptr<const Image> preview;
    int previewFactor = 1;
    std::optional<Metrics> metrics;           // against the reference, when both exist at the same size
    std::optional<Metrics> regionMetrics;     // the same over the user's region
    // The pair `metrics` were computed of: until a new pair's metrics arrive (~100 ms), the last ones stay shown
    // rather than a flicker of "waiting".
    std::shared_ptr<const Image> metricsImage, metricsAgainst;
    // HDR-FLIP (flip.h) of the view against its comparand, computed after the metrics in the background pool, one job
    // per view at a time (a 640 x 360 pair takes ~0.4 s on two cores): its mean over the image and over the user's
    // region, the error map, and the pair it is of (during a progressive render, a recent one; the current one once
    // the view settles).
    std::optional<double> flip, regionFlip;
    std::shared_ptr<const std::vector<float>> flipMap;
    std::shared_ptr<const Image> flipImage, flipAgainst;
    // Whether `flip` is of the metrics' pair (captions and the Metrics dock show it only then).
    bool flipIsCurrent() const { return flip && flipImage == metricsImage && flipAgainst == metricsAgainst; }
    std::shared_ptr<const Image> snapshot;    // the snapshot this view is compared against (null: the reference)
    QString snapshotName;
    std::shared_ptr<const Image> alternate;   // another view's image chosen as the reference (Shift+1-9)
    QString alternateName;
    bool chosenReference = false;             // this view's image is every other view's reference (Shift+1-9)
    QString error;                            // the last render's failure
    bool file = false;                        // an image opened from a file (image_file.h): read-only, not rendered
};

// A mark on every rendered view (not on images from files): where an impulse pushed the particles, in image pixels,
// drawn as a circle of the push's radius with a cross at its centre, fading (opacity) as the push dies out.
struct ImageMarker {
    QPointF centre;
    double radius = 0.0;   // pixels
    double opacity = 1.0;  // (0, 1]
    QString label;         // beside it ("push at step 45")
};

struct CompositorState {
    Layout layout = Layout::Grid;
    int current = 0;             // the view of the single and split layouts
    bool showReference = false;  // single: the reference instead of the view (Shift held)
    double split = 0.5;          // split: the divider's position across the image, [0, 1]
    bool swapped = false;        // split: the reference on the left
    DiffMode diff = DiffMode::Off;
    double exposureOffset = 0.0; // EV added to every view's exposure (E / Shift+E)
    // The display transform of every view (the Display box, M cycles; not of differences): an OpenColorIO display
    // and view, or Tyndall's own operator (false colour adds its colour bar).
    DisplayTransform displayTransform;
    QRect region;                // image pixels; empty for none: drawn on every view, metrics over it
    double zoom = 1.0;           // >= 1, the same for every view (synchronized)
    QPointF centre{0.5, 0.5};    // what the views centre on, in [0, 1]^2 of the image
    bool smoothPreviews = false;       // reduced images scaled up bilinearly (else nearest, showing their pixels)
    std::vector<ImageMarker> markers;  // the recent impulses (Studio::updateImpulseMarkers)
};

// The part of an image of `size` that the views show under the zoom and centre, in image pixels.
QRectF visiblePart(QSize size, const CompositorState& state);

// What a view's tile shows: the reduced preview while there is one (newer than the image), else the image.
const std::shared_ptr<const Image>& shownImage(const ViewFrame& frame);

// The image a view is compared against: its snapshot when one is chosen, else the view chosen as the reference,
// else its reference.
const std::shared_ptr<const Image>& comparand(const ViewFrame& frame);

// The two images the view's comparisons (metrics, difference, convergence, export) are made of. Against the reference:
// the image and reference of one state (stale when they are not the current ones; both null, "waiting", before the
// first such pair). Against a snapshot or another view: the image and the user's choice.
// A reference is compared with once it has this many samples (or all it renders, when that is fewer), or is done: a
// reference of 1-4 spp is noise, its numbers meaningless, and its variance (the "ref. noise" of the metrics) cannot
// be estimated from so few samples. Until then the view keeps comparing the last pair that qualified, marked stale.
constexpr int kMinComparedReferenceSpp = 16;
bool referenceComparable(const ViewFrame& frame);

struct ComparisonPair {
    std::shared_ptr<const Image> image, against;
    bool stale = false;
};
ComparisonPair comparisonPair(const ViewFrame& frame);
ComparisonPair referencePair(const ViewFrame& frame);  // the same against the reference, whatever the view compares to
// The reference is not of the view's current state (or missing): what its tile and the wipe say instead of nothing.
bool referenceStale(const ViewFrame& frame);
QString referenceProgress(const ViewFrame& frame);  // "24/64 spp, ETA 10 s", or empty when it is done
// The caption under a view's tile of `width` pixels, as drawn in `font` at 12 px: the label (name, rendering, technique,
// frame time, spp) and, for a view, its metrics; each in full when it fits, else compact, elided at the end.
QStringList tileCaption(const ViewFrame& frame, bool reference, int width, const QFont& font);
// Why the view's pair cannot be compared ("sizes differ: 16 x 12 against 96 x 72"; an image opened from a file may
// have any size), or empty.
QString incomparable(const ViewFrame& frame);

// Linear RGB to 8-bit display values after 2^exposure through the display transform, like the PNGs the CLI writes
// (within one 8-bit level for Tyndall's sRGB, which takes a table; exactly for the others).
QImage toDisplay(const Image& image, double exposure, const DisplayTransform& transform = {});

// The difference scale shared by every view: 10 % of the mean luminance of the references (or of the image chosen as
// the reference, Shift+1-9), 1e-3 without any.
double sharedDifferenceScale(const std::vector<ViewFrame>& frames);

// The rectangles the views occupy in a frame of `size` under `state`, in view order (an empty rectangle for a view
// that is not shown), so that the viewport can map the cursor to a view and a pixel.
std::vector<QRect> viewRects(const std::vector<ViewFrame>& frames, const CompositorState& state, QSize size);

QImage compose(const std::vector<ViewFrame>& frames, const CompositorState& state, QSize size);

}  // namespace tyndall::studio
