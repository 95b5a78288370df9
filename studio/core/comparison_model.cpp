#include "comparison_model.h"

#include "tyndall/image/flip.h"

#include "tyndall/image/metrics.h"

#include <QMetaObject>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

namespace tyndall::studio {

ComparisonModel::ComparisonModel(Background& background, QObject* parent) : QObject(parent), background_(background) {}

ComparisonModel::~ComparisonModel() {
    while (jobsInFlight_.load() > 0)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void ComparisonModel::runInBackground(std::function<void()> work) {
    ++jobsInFlight_;
    background_.run([this, work = std::move(work)] {
        work();
        --jobsInFlight_;  // the last use of `this`
    });
}

void ComparisonModel::reset(const std::vector<ViewInfo>& views) {
    projectViews_ = int(views.size());
    frames_.assign(views.size() + images_.size(), ViewFrame{});
    for (std::size_t i = 0; i < views.size(); ++i) {
        frames_[i].name = views[i].name;
        frames_[i].technique = views[i].technique;
        frames_[i].exposure = views[i].exposure;
        frames_[i].state = views[i].state;
    }
    for (std::size_t k = 0; k < images_.size(); ++k) {
        ViewFrame& f = frames_[views.size() + k];
        f.name = images_[k].name;
        f.technique = images_[k].kind;
        f.image = images_[k].image;
        f.file = true;
        images_[k].against = std::clamp(images_[k].against, 0, std::max(0, projectViews_ - 1));
    }
    progress_.assign(frames_.size(), {});
    jobs_.assign(frames_.size(), {});
    region_ = QRect();
    referenceView_ = -1;
    syncImages();
    emit framesChanged();
    emit metricsChanged();
    emit convergenceChanged();
}

void ComparisonModel::followViews(const std::vector<ViewInfo>& views, const std::vector<int>& oldOf) {
    const int before = projectViews_;
    std::vector<int> newOf(std::size_t(size()), -1);  // per old view, its new index (-1: gone)
    for (std::size_t i = 0; i < views.size(); ++i)
        if (oldOf[i] >= 0 && oldOf[i] < before) newOf[std::size_t(oldOf[i])] = int(i);
    for (std::size_t k = 0; k < images_.size(); ++k)
        newOf[std::size_t(before) + k] = int(views.size() + k);

    std::vector<ViewFrame> frames(views.size() + images_.size());
    std::vector<std::vector<Progress>> progress(frames.size());
    std::vector<ViewJobs> jobs(frames.size());
    for (std::size_t o = 0; o < newOf.size(); ++o) {
        if (newOf[o] < 0) continue;
        const std::size_t i = std::size_t(newOf[o]);
        frames[i] = std::move(frames_[o]);
        progress[i] = std::move(progress_[o]);
        jobs[i] = jobs_[o];
    }
    for (std::size_t i = 0; i < views.size(); ++i) {
        ViewFrame& f = frames[i];
        f.name = views[i].name;
        f.technique = views[i].technique;
        f.exposure = views[i].exposure;
        f.state = views[i].state;
    }
    frames_ = std::move(frames);
    progress_ = std::move(progress);
    jobs_ = std::move(jobs);
    projectViews_ = int(views.size());
    for (ImageView& image : images_) {
        const int against = image.against < int(newOf.size()) ? newOf[std::size_t(image.against)] : -1;
        image.against = std::clamp(against, 0, std::max(0, projectViews_ - 1));
    }
    referenceView_ =
        referenceView_ >= 0 && referenceView_ < int(newOf.size()) ? newOf[std::size_t(referenceView_)] : -1;
    syncImages();
    refreshAlternates();
    for (std::size_t i = 0; i < views.size(); ++i)
        if (oldOf[i] < 0) updateMetrics(int(i));
    emit metricsChanged();
    emit convergenceChanged();
    emit framesChanged();
}

int ComparisonModel::viewOfMetrics(quint64 request) const {
    const auto it = std::find_if(jobs_.begin(), jobs_.end(), [&](const ViewJobs& j) { return j.metrics == request; });
    return it == jobs_.end() ? -1 : int(it - jobs_.begin());
}

int ComparisonModel::viewOfFlip(quint64 request) const {
    const auto it = std::find_if(jobs_.begin(), jobs_.end(), [&](const ViewJobs& j) { return j.flip == request; });
    return it == jobs_.end() ? -1 : int(it - jobs_.begin());
}

void ComparisonModel::setState(int view, quint64 state) {
    if (view < 0 || view >= projectViews_ || frames_[std::size_t(view)].state == state) return;
    frames_[std::size_t(view)].state = state;
    syncImages();
    emit framesChanged();
}

int ComparisonModel::addImage(const QString& name, const QString& kind, std::shared_ptr<const Image> image,
                              int against) {
    images_.push_back({name, kind, std::move(image), std::clamp(against, 0, std::max(0, projectViews_ - 1))});
    ViewFrame f;
    f.name = name;
    f.technique = kind;
    f.image = images_.back().image;
    f.file = true;
    frames_.push_back(std::move(f));
    progress_.emplace_back();
    jobs_.emplace_back();
    syncImages();
    if (referenceView_ >= 0) refreshAlternates();
    emit metricsChanged();
    emit framesChanged();
    return size() - 1;
}

int ComparisonModel::imageAgainst(int view) const {
    return isImage(view) ? images_[std::size_t(view - projectViews_)].against : -1;
}

void ComparisonModel::setImageAgainst(int view, int against) {
    if (!isImage(view) || against < 0 || against >= projectViews_) return;
    images_[std::size_t(view - projectViews_)].against = against;
    syncImages();
    emit metricsChanged();
    emit framesChanged();
}

void ComparisonModel::renameImage(int view, const QString& name) {
    if (!isImage(view) || name.isEmpty()) return;
    images_[std::size_t(view - projectViews_)].name = name;
    frames_[std::size_t(view)].name = name;
    emit metricsChanged();
    emit framesChanged();
}

void ComparisonModel::removeImage(int view) {
    if (!isImage(view)) return;
    images_.erase(images_.begin() + (view - projectViews_));
    frames_.erase(frames_.begin() + view);
    progress_.erase(progress_.begin() + view);
    jobs_.erase(jobs_.begin() + view);
    if (referenceView_ == view) referenceView_ = -1;
    if (referenceView_ > view) --referenceView_;
    refreshAlternates();
    emit convergenceChanged();
}

void ComparisonModel::syncImages() {
    for (std::size_t k = 0; k < images_.size(); ++k) {
        const int view = projectViews_ + int(k);
        ViewFrame& f = frames_[std::size_t(view)];
        const ViewFrame* a = images_[k].against < projectViews_ ? &frames_[std::size_t(images_[k].against)] : nullptr;
        // The file is of no state: it stands for the current state of the view it is compared with, so that it pairs
        // with that view's reference of the current state, and with the last one (stale) while a new one renders.
        const quint64 state = a ? a->state : 1;
        const std::shared_ptr<const Image> reference = a ? a->reference : nullptr;
        const bool changed = f.reference != reference || f.state != state || (a && f.referenceState != a->referenceState);
        f.state = f.imageState = state;
        f.reference = reference;
        f.referenceState = a ? a->referenceState : 0;
        f.referenceSpp = a ? a->referenceSpp : 0;
        f.referenceCached = a && a->referenceCached;
        f.referenceRendering = a && a->referenceRendering;
        f.referenceTargetSpp = a ? a->referenceTargetSpp : 0;
        f.referenceEta = a ? a->referenceEta : -1.0;
        if (f.reference && f.referenceState == f.imageState && referenceComparable(f)) {
            f.pairImage = f.image;
            f.pairReference = f.reference;
        } else if (!a) {
            f.pairImage.reset();
            f.pairReference.reset();
        }
        if (changed) updateMetrics(view);
    }
}

void ComparisonModel::setTechniqueLabel(int view, const QString& label) {
    if (view < 0 || view >= projectViews_ || frames_[std::size_t(view)].technique == label) return;
    frames_[std::size_t(view)].technique = label;
    emit framesChanged();
}

void ComparisonModel::setExposure(int view, double exposure) {
    if (view < 0 || view >= size() || frames_[std::size_t(view)].exposure == exposure) return;
    frames_[std::size_t(view)].exposure = exposure;
    // The metrics of the image shown depend on the exposure (PSNR), not on the parameters: a parameter edit leaves
    // them to its own image, instead of recomputing the old one's while the new one renders.
    updateMetrics(view);
    emit metricsChanged();
    emit framesChanged();
}

void ComparisonModel::renderStarted(int view, bool reference, int targetSpp) {
    if (view < 0 || view >= size()) return;
    ViewFrame& f = frames_[std::size_t(view)];
    if (reference) {
        f.referenceRendering = true;
        f.referenceEta = -1.0;
        f.referenceTargetSpp = targetSpp;
        emit metricsChanged();  // the status names the reference
    } else {
        f.rendering = true;
    }
    if (reference) syncImages();
    emit framesChanged();
}

void ComparisonModel::renderStopped(int view, bool reference) {
    if (view < 0 || view >= size()) return;
    ViewFrame& f = frames_[std::size_t(view)];
    (reference ? f.referenceRendering : f.rendering) = false;
    if (reference) f.referenceEta = -1.0;
    flipWhenIdle();
    emit metricsChanged();  // the status
    emit framesChanged();
}

void ComparisonModel::renderFailed(int view, const QString& error) {
    if (view < 0 || view >= size()) return;
    frames_[std::size_t(view)].error = error;
    emit framesChanged();
}

void ComparisonModel::addOutput(const RenderOutput& out) {
    if (out.view < 0 || out.view >= size()) return;
    ViewFrame& f = frames_[std::size_t(out.view)];
    if (out.factor > 1) {
        // A reduced image of the progressive resolution: shown until the full one arrives, never compared, exported
        // or plotted (the image, the pair and the metrics stay the last full ones).
        if (!out.image) return;
        f.preview = out.image;
        f.previewFactor = out.factor;
        emit framesChanged();
        return;
    }
    if (!out.reference) f.preview.reset();  // a full image (or the render's failure) of the view
    if (!out.error.isEmpty()) {
        f.error = out.error;
    } else if (out.reference) {
        f.reference = out.image;
        f.referenceState = out.state;
        f.referenceSpp = out.spp;
        f.referenceCached = out.cached;
        if (out.targetSpp > 0) f.referenceTargetSpp = out.targetSpp;
        // Estimated from this render's own pace (an interrupted reference starts again from zero).
        f.referenceEta = out.final || out.spp <= 0 || f.referenceTargetSpp <= out.spp
                             ? -1.0
                             : out.seconds / out.spp * (f.referenceTargetSpp - out.spp);
    } else {
        f.image = out.image;
        f.imageState = out.state;
        f.spp = out.spp;
        f.seconds = out.seconds;
        f.error.clear();
    }
    if (out.final) (out.reference ? f.referenceRendering : f.rendering) = false;
    if (out.reference) syncImages();
    if (f.image && f.reference && f.imageState == f.referenceState && referenceComparable(f)) {
        f.pairImage = f.image;  // the newest pair of one state: what comparisons use while the other catches up
        f.pairReference = f.reference;
    }
    if (!out.reference && out.image) {
        Progress point{out.spp, out.seconds, out.image};
        point.state = out.state;
        addConvergencePoint(progress_[std::size_t(out.view)], std::move(point));
    }
    if (!out.reference && out.view == referenceView_) refreshAlternates();
    updateMetrics(out.view);
    if (out.final) flipWhenIdle();
    updateConvergence();
    emit metricsChanged();
    emit framesChanged();
}

void ComparisonModel::setRegion(QRect region) {
    region_ = region;
    for (int i = 0; i < size(); ++i)
        updateMetrics(i);
    emit metricsChanged();
    emit framesChanged();
}

void ComparisonModel::compareWithSnapshot(int view, std::shared_ptr<const Image> image, const QString& name) {
    for (ViewFrame& f : frames_) {
        f.snapshot.reset();
        f.snapshotName.clear();
    }
    if (view >= 0 && view < size() && image) {
        frames_[std::size_t(view)].snapshot = std::move(image);
        frames_[std::size_t(view)].snapshotName = name;
    }
    for (int i = 0; i < size(); ++i)
        updateMetrics(i);
    emit metricsChanged();
    emit framesChanged();
}

void ComparisonModel::chooseReferenceView(int view) {
    referenceView_ = view >= 0 && view < size() ? view : -1;
    refreshAlternates();
}

void ComparisonModel::refreshAlternates() {
    for (int i = 0; i < size(); ++i) {
        ViewFrame& f = frames_[std::size_t(i)];
        const bool use = referenceView_ >= 0 && i != referenceView_;
        f.chosenReference = i == referenceView_;
        const std::shared_ptr<const Image> alternate = use ? frames_[std::size_t(referenceView_)].image : nullptr;
        if (alternate == f.alternate) continue;
        f.alternate = alternate;
        f.alternateName = use ? frames_[std::size_t(referenceView_)].name : QString();
        updateMetrics(i);
    }
    updateConvergence();  // the plot follows the choice, too
    emit metricsChanged();
    emit framesChanged();
}

void ComparisonModel::updateMetrics(int view) {
    // Off the GUI thread (a 512 x 512 comparison takes ~100 ms with the renders on both cores).
    ViewFrame& f = frames_[std::size_t(view)];
    const ComparisonPair pair = comparisonPair(f);
    f.metricsStale = pair.stale;
    const std::shared_ptr<const Image> image = pair.image, against = pair.against;
    if (!image || !against || image->width() != against->width() || image->height() != against->height()) {
        f.metrics.reset();
        f.regionMetrics.reset();
        f.metricsImage.reset();
        f.metricsAgainst.reset();
        jobs_[std::size_t(view)].metrics = 0;
        updateFlip(view);
        return;
    }
    updateFlip(view);
    // The numbers shown stay until the new pair's arrive: no flicker of "waiting" at every progressive image.
    const double exposure = f.exposure;
    const QRect region = region_.intersected(QRect(0, 0, image->width(), image->height()));
    ++metricsPending_;
    const quint64 request = ++metricsRequests_;
    jobs_[std::size_t(view)].metrics = request;
    runInBackground([this, image, against, exposure, region, request] {
        std::optional<Metrics> whole, part;
        try {
            whole = computeMetrics(*image, *against, exposure);
            if (!region.isEmpty())
                part = computeMetrics(*image, *against, exposure, {region.x(), region.y(), region.width(), region.height()});
        } catch (const std::exception&) {
            // Images that cannot be compared (a channel missing) show no numbers.
        }
        QMetaObject::invokeMethod(
            this,
            [this, image, against, whole, part, request] {
                --metricsPending_;
                // The view that asked (it may have moved since: views authored before it). Stale: a later request for
                // it (a new image, reference, exposure or region) may finish first, in the pool's order, and must not
                // be overwritten by this one.
                const int view = viewOfMetrics(request);
                if (view < 0) return;
                ViewFrame& f = frames_[std::size_t(view)];
                const ComparisonPair now = comparisonPair(f);
                if (now.image != image || now.against != against) return;
                f.metrics = whole;
                f.regionMetrics = part;
                f.metricsImage = image;
                f.metricsAgainst = against;
                emit metricsChanged();
                emit framesChanged();
            },
            Qt::QueuedConnection);
    });
}

namespace {

// The mean of a FLIP error map (row-major, `width` pixels across) over `region` (image pixels; empty: none).
std::optional<double> flipMean(const std::vector<float>& map, int width, QRect region) {
    if (region.isEmpty()) return std::nullopt;
    return flipRegionMean(map, width, region.x(), region.y(), region.width(), region.height());
}

}  // namespace

void ComparisonModel::updateFlip(int view) {
    ViewFrame& f = frames_[std::size_t(view)];
    const ComparisonPair pair = comparisonPair(f);
    const std::shared_ptr<const Image> image = pair.image, against = pair.against;
    if (!image || !against || image->width() != against->width() || image->height() != against->height()) {
        f.flip.reset();
        f.regionFlip.reset();
        f.flipMap.reset();
        f.flipImage.reset();
        f.flipAgainst.reset();
        return;
    }
    const QRect region = region_.intersected(QRect(0, 0, image->width(), image->height()));
    if (f.flipMap && f.flipImage == image && f.flipAgainst == against) {
        f.regionFlip = flipMean(*f.flipMap, image->width(), region);  // a sum over the stored map: no FLIP
        return;
    }
    if (jobs_[std::size_t(view)].flip != 0) return;  // it asks again for the newest pair when it ends
    // Not while anything renders: even on one niced thread, FLIP beside the renders held back an edit's first images
    // (Studio.Gui.Rendering under load). flipWhenIdle() starts it when the last render ends.
    if (anyRendering()) return;
    ++flipPending_;
    const quint64 request = ++metricsRequests_;
    jobs_[std::size_t(view)].flip = request;
    runInBackground([this, image, against, request] {
        std::shared_ptr<const std::vector<float>> map;
        // On this (niced) pool thread alone: on TBB's workers, at full priority and beside the CPU renders' tasks,
        // FLIP took their time from the edit's images.
        HdrFlipSettings alone;
        alone.threads = 1;
        try {
            map = std::make_shared<const std::vector<float>>(hdrFlip(*against, *image, alone).error);
        } catch (const std::exception&) {
            // No R, G, B to compare: no FLIP, as no metrics.
        }
        QMetaObject::invokeMethod(
            this,
            [this, image, against, map, request] {
                --flipPending_;
                const int view = viewOfFlip(request);
                if (view < 0) return;  // the views started again
                jobs_[std::size_t(view)].flip = 0;
                ViewFrame& f = frames_[std::size_t(view)];
                const ComparisonPair now = comparisonPair(f);
                const bool sameSize =
                    now.image && now.image->width() == image->width() && now.image->height() == image->height();
                if (map && sameSize) {
                    f.flipMap = map;
                    f.flipImage = image;
                    f.flipAgainst = against;
                    f.flip = flipMean(*map, image->width(), QRect(0, 0, image->width(), image->height()));
                    f.regionFlip = flipMean(*map, image->width(),
                                            region_.intersected(QRect(0, 0, image->width(), image->height())));
                }
                // The pair moved on while it ran (a progressive image, a new reference): FLIP of the newest.
                if (now.image != image || now.against != against) updateFlip(view);
                emit metricsChanged();
                emit framesChanged();
            },
            Qt::QueuedConnection);
    });
}

bool ComparisonModel::anyRendering() const {
    return std::any_of(frames_.begin(), frames_.end(),
                       [](const ViewFrame& f) { return f.rendering || f.referenceRendering; });
}

void ComparisonModel::flipWhenIdle() {
    if (anyRendering()) return;
    for (int i = 0; i < size(); ++i)
        updateFlip(i);
}

int ComparisonModel::convergenceBucket(int spp) {
    return spp > 0 ? int(std::floor(4.0 * std::log2(double(spp)))) : -1;
}

void ComparisonModel::updateConvergence() {
    // The relMSE of each progressive image against its view's comparand, without tonemapping. A new reference makes
    // every image of its view stale, and each costs ~4 ms at 512 x 512: computed in the background pool.
    struct Item {
        std::shared_ptr<const Image> image, reference;
        bool alternate = false;
        double relMSE = 0.0;
    };
    std::vector<Item> items;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
        // Against the view chosen as every view's reference (Shift+1-9), else the reference of the image's state.
        const bool alternate = bool(frames_[i].alternate);
        const std::shared_ptr<const Image>& reference = alternate ? frames_[i].alternate : frames_[i].reference;
        if (!reference) continue;
        for (std::size_t k = 0; k < progress_[i].size(); ++k) {
            Progress& p = progress_[i][k];
            // Only images of one state compare, and only with a reference of enough samples.
            if (!alternate && (p.state != frames_[i].referenceState || !referenceComparable(frames_[i]))) continue;
            if (p.image->width() != reference->width() || p.image->height() != reference->height()) continue;
            if (p.against == reference || p.requested == reference) continue;
            p.requested = reference;
            items.push_back({p.image, reference, alternate});
        }
    }
    emit convergenceChanged();
    if (items.empty()) return;
    ++convergencePending_;
    runInBackground([this, items = std::move(items)]() mutable {
        for (Item& item : items) {
            const Image &a = *item.image, &r = *item.reference;
            double sum = 0.0;
            for (int y = 0; y < a.height(); ++y)
                for (int x = 0; x < a.width(); ++x)
                    for (int c = 0; c < 3; ++c) {
                        const double ref = r.at(x, y, c), d = a.at(x, y, c) - ref;
                        sum += d * d / (ref * ref + 0.01);  // relMSE, as in metrics.h
                    }
            item.relMSE = sum / (3.0 * a.width() * a.height());
        }
        QMetaObject::invokeMethod(this, [this, items = std::move(items)] {
            --convergencePending_;
            for (const Item& item : items) {
                // The view may have started a new render (its images cleared) or moved (views authored before it)
                // since the job was made: the point is found by its image.
                Progress* point = nullptr;
                for (auto& points : progress_)
                    for (Progress& p : points)
                        if (p.image == item.image) point = &p;
                if (!point) continue;
                Progress& p = *point;
                p.relMSE = item.relMSE;
                p.against = item.reference;
                p.againstAlternate = item.alternate;
                if (p.requested == item.reference) p.requested.reset();
            }
            emit convergenceChanged();
        }, Qt::QueuedConnection);
    });
}

void ComparisonModel::convergenceSeries(std::vector<QString>& names,
                                        std::vector<std::vector<ConvergencePoint>>& points) const {
    names.clear();
    points.clear();
    for (std::size_t i = 0; i < frames_.size(); ++i) {
        names.push_back(frames_[i].name);
        points.emplace_back();
        const ViewFrame& f = frames_[i];
        for (const Progress& p : progress_[i]) {
            const bool valid = f.alternate ? p.againstAlternate && p.against == f.alternate
                                           : !p.againstAlternate && p.against && p.state == f.referenceState;
            if (p.relMSE >= 0.0 && valid) points.back().push_back({p.spp, p.seconds, p.relMSE});
        }
    }
}

}  // namespace tyndall::studio
