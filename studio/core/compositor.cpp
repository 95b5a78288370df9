#include "compositor.h"

#include "tyndall/core/error.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/flip.h"
#include "tyndall/image/image_io.h"

#include <QFontMetrics>
#include <QPainter>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>

namespace tyndall::studio {

namespace {

constexpr int kLabelHeight = 36;  // px under each image for its label
// px kept free at the bottom of the frame for the colour bar of a difference or false-colour mode, so that it never
// covers the bottom tiles' captions (it did, also in the exported viewport.png).
constexpr int kColourBarStrip = 34;

double luminance(const Image& image, int x, int y) {
    return 0.2126 * image.at(x, y, 0) + 0.7152 * image.at(x, y, 1) + 0.0722 * image.at(x, y, 2);
}

// The largest rectangle of the image's aspect ratio inside `cell`, centred.
QRect fit(QSize imageSize, QRect cell) {
    if (imageSize.isEmpty() || cell.isEmpty()) return {};
    const double scale = std::min(double(cell.width()) / imageSize.width(), double(cell.height()) / imageSize.height());
    const QSize s(std::max(1, int(imageSize.width() * scale)), std::max(1, int(imageSize.height() * scale)));
    return QRect(cell.x() + (cell.width() - s.width()) / 2, cell.y() + (cell.height() - s.height()) / 2, s.width(),
                 s.height());
}

QSize imageSizeOf(const std::vector<ViewFrame>& frames) {
    for (const ViewFrame& f : frames) {
        if (f.image) return QSize(f.image->width(), f.image->height());
        if (f.reference) return QSize(f.reference->width(), f.reference->height());
    }
    return QSize(4, 3);
}

// The cells of the layout: a grid of N views, or one.
std::vector<QRect> cells(const std::vector<ViewFrame>& frames, const CompositorState& state, QSize size) {
    std::vector<QRect> out(frames.size());
    if (frames.empty()) return out;
    const QSize imageSize = imageSizeOf(frames);
    if (state.diff != DiffMode::Off || state.displayTransform.falseColour())
        size.setHeight(std::max(1, size.height() - kColourBarStrip));
    if (state.layout != Layout::Grid) {
        const int current = std::clamp(state.current, 0, int(frames.size()) - 1);
        out[std::size_t(current)] = fit(imageSize, QRect(0, 0, size.width(), size.height() - kLabelHeight));
        return out;
    }
    // The grid of columns x rows that shows the images largest.
    const int n = int(frames.size());
    int bestColumns = 1;
    double bestScale = 0.0;
    for (int columns = 1; columns <= n; ++columns) {
        const int rows = (n + columns - 1) / columns;
        const double scale = std::min(double(size.width()) / columns / imageSize.width(),
                                      double(size.height() / rows - kLabelHeight) / imageSize.height());
        if (scale > bestScale) {
            bestScale = scale;
            bestColumns = columns;
        }
    }
    const int rows = (n + bestColumns - 1) / bestColumns;
    const int cellWidth = size.width() / bestColumns, cellHeight = size.height() / rows;
    for (int i = 0; i < n; ++i) {
        const QRect cell((i % bestColumns) * cellWidth, (i / bestColumns) * cellHeight, cellWidth,
                         cellHeight - kLabelHeight);
        out[std::size_t(i)] = fit(imageSize, cell);
    }
    return out;
}

// Displayed images, cached: composing runs on the GUI thread at every render output and every key press, and
// tonemapping a 512 x 512 image costs ~10 ms. Images are immutable once shared, so an entry stays valid while its images
// are alive (weak pointers tell).
struct DisplayEntry {
    std::weak_ptr<const Image> image, against;
    const Image* imageKey = nullptr;
    const Image* againstKey = nullptr;
    double exposure = 0.0, scale = 0.0;
    std::size_t mode = 0;  // the difference mode, or 16 + a hash of the display transform
    QImage display;
};

template <typename Make>
QImage cachedDisplay(const std::shared_ptr<const Image>& image, const std::shared_ptr<const Image>& against,
                     double exposure, std::size_t mode, double scale, Make&& make) {
    thread_local std::vector<DisplayEntry> cache;  // per composing thread
    for (auto it = cache.begin(); it != cache.end();) {
        if (it->image.expired() || (it->againstKey && it->against.expired())) {
            it = cache.erase(it);
            continue;
        }
        if (it->imageKey == image.get() && it->againstKey == against.get() && it->exposure == exposure &&
            it->mode == mode && it->scale == scale)
            return it->display;
        ++it;
    }
    DisplayEntry e{image, against, image.get(), against.get(), exposure, scale, mode, make()};
    cache.push_back(e);
    if (cache.size() > 48) cache.erase(cache.begin());
    return e.display;
}

// sharedDifferenceScale() sums every reference (1.5 M pixels for six views): once per set of references.
double cachedDifferenceScale(const std::vector<ViewFrame>& frames) {
    thread_local std::vector<const Image*> keys;  // per composing thread
    thread_local std::vector<std::weak_ptr<const Image>> alive;
    thread_local double scale = 0.0;
    bool same = keys.size() == frames.size();
    for (std::size_t i = 0; same && i < frames.size(); ++i)
        same = keys[i] == frames[i].reference.get() && (!keys[i] || !alive[i].expired());
    if (same) return scale;
    keys.clear();
    alive.clear();
    for (const ViewFrame& f : frames) {
        keys.push_back(f.reference.get());
        alive.push_back(f.reference);
    }
    return scale = sharedDifferenceScale(frames);
}

// HDR-FLIP's error map of `image` against `reference` (the automatic exposure range, 67 pixels per degree), through
// magma: black where they cannot be told apart, pale yellow at 1.
QImage flipDisplay(const Image& image, const Image& reference) {
    HdrFlipResult flip;
    try {
        flip = hdrFlip(reference, image);
    } catch (const InputError&) {
        return {};  // no R, G, B to compare: the tile says that the difference waits
    }
    return toDisplay(flipColourMap(flip.error, image.width(), image.height()), 0.0);
}

QImage differenceDisplay(const Image& image, const Image& reference, DiffMode mode, double scale) {
    if (mode == DiffMode::Flip) return flipDisplay(image, reference);
    const DifferenceKind kind = mode == DiffMode::Signed     ? DifferenceKind::Signed
                                : mode == DiffMode::Absolute ? DifferenceKind::Absolute
                                                             : DifferenceKind::Relative;
    const double s = mode == DiffMode::Relative ? 0.1 : scale;  // relative error: 10 % at the map's end
    return toDisplay(differenceImage(image, reference, kind, s), 0.0);
}

QString number(double v) {
    return QString::number(v, 'g', 3);
}

QString comparandName(const ViewFrame& f) {
    return f.snapshot ? "snapshot " + f.snapshotName : f.alternate ? "view " + f.alternateName : QString("reference");
}

// A tile's caption, in full or compact (for a narrow tile: without the technique's name, which the Views dock lists,
// and with a short note for a partial scene).
QString labelOf(const ViewFrame& f, bool reference, bool compact = false) {
    if (!f.error.isEmpty()) return f.name + "  -  " + f.error.left(120);
    // What changes (rendering, stale, progress) comes first: a narrow tile elides the end of its caption.
    QString line = f.name, details;
    if (reference) {
        line += "  -  " + comparandName(f);
        if (!f.snapshot && !f.alternate) {
            const QString progress = referenceProgress(f);
            if (f.reference && referenceStale(f)) line += " (stale)";
            if (!progress.isEmpty())
                line += "  " + progress;
            else if (f.reference)
                details = QString("  %1 spp%2").arg(f.referenceSpp).arg(f.referenceCached ? " (cached)" : "");
        }
    } else {
        if (f.rendering) line += " (rendering)";
        if (f.preview && shownImage(f) == f.preview) {
            const auto reduced = f.preview->metadata.find("reducedWork");
            line += QString(" (1/%1 resolution%2)")
                        .arg(f.previewFactor)
                        .arg(reduced == f.preview->metadata.end() ? QString()
                                                                  : ", " + QString::fromStdString(reduced->second));
        }
        if (!compact) line += "  -  " + f.technique;
        if (f.image && !f.file && shownImage(f) == f.image) {
            details = QString("  %1 ms").arg(f.seconds * 1e3, 0, 'f', 0);
            if (f.spp > 1) details += QString("  %1 spp").arg(f.spp);
        }
    }
    const Image* shown = reference ? f.reference.get() : shownImage(f).get();
    // The frame of the particle animation the image shows (views lag behind play at their own rates).
    if (shown && shown->metadata.count("animationFrame")) {
        const QString frame = QString::fromStdString(shown->metadata.at("animationFrame"));
        line += "  " + (compact ? frame.section(" (", 0, 0) : frame);
    }
    // A view without its own lights/media renders what its technique supports: say that the scene is not all there.
    // The Views list's tooltip says what, when the caption has no room for it.
    if (shown && shown->metadata.count("leftOut"))
        line += compact ? "  (partial: see the Views list)"
                        : "  (leaves out " + QString::fromStdString(shown->metadata.at("leftOut")) + ")";
    return line + details;
}

// The metrics under a tile: in full, compact (relMSE and PSNR without their long names, and the region's relMSE) or
// minimal (without the region's, which the Metrics dock lists).
enum class Detail { Full, Compact, Minimal };
QString metricsLine(const ViewFrame& f, Detail detail = Detail::Full) {
    const bool compact = detail != Detail::Full;
    if (!f.metrics) {
        if (const QString why = incomparable(f); !why.isEmpty()) return "no metrics: " + why;
        if (f.chosenReference && !f.snapshot) return "the other views' reference (Shift+1-9)";
        if (f.snapshot || f.alternate || !f.image) return {};
        return "metrics waiting for the reference" + (referenceProgress(f).isEmpty() ? QString() : ": " + referenceProgress(f));
    }
    // A view that is its own reference (the path tracer with the reference's settings and seed): no error to show,
    // rather than relMSE 0 and an infinite PSNR.
    if (f.metrics->relMSE == 0.0 && f.metricsImage && f.metricsAgainst && !f.snapshot && !f.alternate)
        return compact ? QString("identical to the reference")
                       : QString("identical to its reference (the same renderer, settings and seed)");
    const QString progress = referenceProgress(f);
    // HDR-FLIP follows the metrics (its own background job, once nothing renders): shown when it is of their pair.
    const bool flipCurrent = f.flipIsCurrent();
    const QString flip = flipCurrent ? "  FLIP " + number(*f.flip) : QString();
    if (compact) {
        QString line = QString(f.metricsStale ? "stale: " : "") + "relMSE " + number(f.metrics->relMSE) + "  " +
                       number(f.metrics->psnr) + " dB" + flip;
        if (f.regionMetrics && detail == Detail::Compact) line += "  | region " + number(f.regionMetrics->relMSE);
        return line;
    }
    QString line = QString(f.metricsStale ? (progress.isEmpty() ? "stale: " : "stale (" + progress + "): ") : "") +
                   "relMSE " + number(f.metrics->relMSE) + "  PSNR " + number(f.metrics->psnr) + " dB" + flip;
    if (f.metrics->referenceNoiseRelMSE) line += "  ref. noise " + number(*f.metrics->referenceNoiseRelMSE);
    if (f.regionMetrics) line += "  | region relMSE " + number(f.regionMetrics->relMSE);
    if (f.regionMetrics && f.regionFlip && flipCurrent) line += "  FLIP " + number(*f.regionFlip);
    return line;
}

}  // namespace

QString incomparable(const ViewFrame& frame) {
    const ComparisonPair pair = comparisonPair(frame);
    if (!pair.image || !pair.against) return {};
    if (pair.image->width() == pair.against->width() && pair.image->height() == pair.against->height()) return {};
    return QString("sizes differ: %1 x %2 against %3 x %4")
        .arg(pair.image->width())
        .arg(pair.image->height())
        .arg(pair.against->width())
        .arg(pair.against->height());
}

namespace {

// The user's region, from image pixels into the view's rectangle on screen.
void drawRegion(QPainter& p, QRect imageRect, QRectF visible, QRect region) {
    if (region.isEmpty() || visible.isEmpty()) return;
    const double sx = imageRect.width() / visible.width(), sy = imageRect.height() / visible.height();
    const QRect r(imageRect.x() + int((region.x() - visible.x()) * sx), imageRect.y() + int((region.y() - visible.y()) * sy),
                  std::max(1, int(region.width() * sx)), std::max(1, int(region.height() * sy)));
    p.setClipRect(imageRect);
    p.setPen(QPen(QColor(255, 220, 0), 1, Qt::DashLine));
    p.setBrush(Qt::NoBrush);
    p.drawRect(r);
    p.setClipping(false);
}

QFont captionFont(QFont font) {
    font.setPixelSize(12);
    return font;
}

// The first of `forms` (from the most to the least detailed) that fits `width`, else the last elided: a caption never
// runs into the next cell of the grid, and a narrow tile keeps its numbers rather than the technique's name.
QString fitted(const QFontMetrics& metrics, int width, const QStringList& forms) {
    for (const QString& form : forms)
        if (metrics.horizontalAdvance(form) <= width) return form;
    return metrics.elidedText(forms.back(), Qt::ElideRight, width);
}

void drawLabel(QPainter& p, QRect imageRect, const QStringList& lines) {
    p.setPen(QColor(230, 230, 230));
    p.setFont(captionFont(p.font()));
    const QRect r(imageRect.x(), imageRect.bottom() + 3, imageRect.width(), 14);
    for (int i = 0; i < lines.size(); ++i)
        if (!lines[i].isEmpty()) p.drawText(r.translated(0, 15 * i), Qt::AlignLeft | Qt::AlignVCenter, lines[i]);
}

// The impulses' markers, from image pixels into the view's rectangle on screen, clipped to it.
void drawMarkers(QPainter& p, QRect imageRect, QRectF visible, const std::vector<ImageMarker>& markers) {
    if (markers.empty() || visible.isEmpty()) return;
    const double sx = imageRect.width() / visible.width(), sy = imageRect.height() / visible.height();
    p.save();
    p.setClipRect(imageRect);
    p.setRenderHint(QPainter::Antialiasing, true);
    p.setBrush(Qt::NoBrush);
    for (const ImageMarker& m : markers) {
        const QPointF c(imageRect.x() + (m.centre.x() - visible.x()) * sx,
                        imageRect.y() + (m.centre.y() - visible.y()) * sy);
        const double rx = std::max(3.0, m.radius * sx), ry = std::max(3.0, m.radius * sy);
        QColor colour(80, 220, 255);
        colour.setAlphaF(float(std::clamp(m.opacity, 0.0, 1.0)));
        p.setPen(QPen(colour, 1.5));
        p.drawEllipse(c, rx, ry);
        p.drawLine(c - QPointF(4, 0), c + QPointF(4, 0));
        p.drawLine(c - QPointF(0, 4), c + QPointF(0, 4));
        if (!m.label.isEmpty()) {
            p.setFont(captionFont(p.font()));
            p.drawText(c + QPointF(rx * 0.71 + 3, -ry * 0.71 - 3), m.label);
        }
    }
    p.restore();
}

}  // namespace

QStringList tileCaption(const ViewFrame& frame, bool reference, int width, const QFont& font) {
    const QFontMetrics metrics(captionFont(font));
    QStringList lines = {fitted(metrics, width, {labelOf(frame, reference), labelOf(frame, reference, true)})};
    if (!reference)
        lines << fitted(metrics, width,
                        {metricsLine(frame), metricsLine(frame, Detail::Compact), metricsLine(frame, Detail::Minimal)});
    return lines;
}

namespace {

void drawColourBar(QPainter& p, QSize size, DiffMode mode, double scale) {
    const int width = std::min(256, size.width() / 3), height = 10;
    const QRect bar(size.width() - width - 12, size.height() - height - 20, width, height);
    for (int x = 0; x < width; ++x) {
        const double t = (x + 0.5) / width;
        const Rgb c = mode == DiffMode::Signed ? diverging(t) : mode == DiffMode::Flip ? magma(t) : viridis(t);
        p.setPen(QColor(int(srgbEncode(float(c.r)) * 255.0f + 0.5f), int(srgbEncode(float(c.g)) * 255.0f + 0.5f),
                        int(srgbEncode(float(c.b)) * 255.0f + 0.5f)));
        p.drawLine(bar.x() + x, bar.y(), bar.x() + x, bar.bottom());
    }
    p.setPen(QColor(230, 230, 230));
    const double end = mode == DiffMode::Relative ? 0.1 : mode == DiffMode::Flip ? 1.0 : scale;
    const QString left = mode == DiffMode::Signed ? "-" + number(end) : "0";
    const QString name = mode == DiffMode::Signed     ? "signed"
                         : mode == DiffMode::Absolute ? "absolute"
                         : mode == DiffMode::Flip     ? "FLIP"
                                                      : "relative";
    p.drawText(QRect(bar.x(), bar.bottom() + 2, width, 14), Qt::AlignLeft, left);
    p.drawText(QRect(bar.x(), bar.bottom() + 2, width, 14), Qt::AlignHCenter, name);
    p.drawText(QRect(bar.x(), bar.bottom() + 2, width, 14), Qt::AlignRight, number(end));
}

// The false-colour map's bar: luminance after exposure, in stops (EV) of 1.
void drawFalseColourBar(QPainter& p, QSize size) {
    const int width = std::min(256, size.width() / 3), height = 10;
    const QRect bar(size.width() - width - 12, size.height() - height - 20, width, height);
    for (int x = 0; x < width; ++x) {
        const Rgb c = viridis((x + 0.5) / width);
        p.setPen(QColor(int(srgbEncode(float(c.r)) * 255.0f + 0.5f), int(srgbEncode(float(c.g)) * 255.0f + 0.5f),
                        int(srgbEncode(float(c.b)) * 255.0f + 0.5f)));
        p.drawLine(bar.x() + x, bar.y(), bar.x() + x, bar.bottom());
    }
    p.setPen(QColor(230, 230, 230));
    p.drawText(QRect(bar.x(), bar.bottom() + 2, width, 14), Qt::AlignLeft, QString::number(kFalseColourMinEv) + " EV");
    p.drawText(QRect(bar.x(), bar.bottom() + 2, width, 14), Qt::AlignHCenter, "log2 luminance");
    p.drawText(QRect(bar.x(), bar.bottom() + 2, width, 14), Qt::AlignRight, "+" + QString::number(kFalseColourMaxEv) + " EV");
}

}  // namespace

QRectF visiblePart(QSize size, const CompositorState& state) {
    const double zoom = std::max(1.0, state.zoom);
    const double w = size.width() / zoom, h = size.height() / zoom;
    const double x = std::clamp(state.centre.x() * size.width() - w / 2, 0.0, size.width() - w);
    const double y = std::clamp(state.centre.y() * size.height() - h / 2, 0.0, size.height() - h);
    return QRectF(x, y, w, h);
}

const std::shared_ptr<const Image>& shownImage(const ViewFrame& frame) {
    // The model keeps a preview only from a reduced image until the full one of its render arrives (a view's own edit
    // does not change its state: the order of arrival, not the state, says which is newer).
    return frame.preview ? frame.preview : frame.image;
}

const std::shared_ptr<const Image>& comparand(const ViewFrame& frame) {
    return frame.snapshot ? frame.snapshot : frame.alternate ? frame.alternate : frame.reference;
}

ComparisonPair comparisonPair(const ViewFrame& frame) {
    if (frame.snapshot || frame.alternate) return {frame.image, comparand(frame), false};
    return referencePair(frame);
}

bool referenceComparable(const ViewFrame& frame) {
    if (!frame.reference) return false;
    if (!frame.referenceRendering || frame.file) return true;
    const int target = frame.referenceTargetSpp > 0 ? frame.referenceTargetSpp : kMinComparedReferenceSpp;
    return frame.referenceSpp >= std::min(kMinComparedReferenceSpp, target);
}

ComparisonPair referencePair(const ViewFrame& frame) {
    if (frame.image && frame.reference && frame.imageState == frame.referenceState && referenceComparable(frame))
        return {frame.image, frame.reference, false};
    return {frame.pairImage, frame.pairReference, bool(frame.pairImage)};
}

bool referenceStale(const ViewFrame& frame) {
    return !frame.reference || frame.referenceState != frame.state;
}

QString referenceProgress(const ViewFrame& frame) {
    if (!frame.referenceRendering) return {};
    QString text = frame.referenceState == frame.state && frame.reference
                       ? QString("%1/%2 spp").arg(frame.referenceSpp).arg(frame.referenceTargetSpp)
                       : QString("rendering");
    if (frame.referenceEta >= 0.0 && frame.referenceState == frame.state)
        text += QString(", ETA %1 s").arg(std::ceil(frame.referenceEta), 0, 'f', 0);
    return "reference " + text;
}

QImage toDisplay(const Image& image, double exposure, const DisplayTransform& transform) {
    QImage out(image.width(), image.height(), QImage::Format_RGBA8888);
    if (transform.isOcio() || transform.tonemap() != Tonemap::Srgb) {
        // The whole image through the transform at once (OpenColorIO's processor, or Tyndall's operator; in
        // parallel, DisplayTransform::apply).
        std::vector<float> rgb(std::size_t(image.width()) * std::size_t(image.height()) * 3);
        const int r = std::max(image.channelIndex("R"), 0), g = std::max(image.channelIndex("G"), 0),
                  b = std::max(image.channelIndex("B"), 0);
        for (int y = 0; y < image.height(); ++y)
            for (int x = 0; x < image.width(); ++x) {
                float* p = rgb.data() + 3 * (std::size_t(y) * std::size_t(image.width()) + std::size_t(x));
                p[0] = image.at(x, y, r), p[1] = image.at(x, y, g), p[2] = image.at(x, y, b);
            }
        transform.apply(rgb.data(), std::size_t(image.width()) * std::size_t(image.height()), exposure);
        for (int y = 0; y < image.height(); ++y) {
            uchar* row = out.scanLine(y);
            const float* p = rgb.data() + 3 * std::size_t(y) * std::size_t(image.width());
            for (int x = 0; x < image.width(); ++x) {
                for (int c = 0; c < 3; ++c)
                    row[4 * x + c] = uchar(std::lround(p[3 * x + c] * 255.0f));
                row[4 * x + 3] = 255;
            }
        }
        return out;
    }
    // Plain sRGB is 2^exposure then the sRGB curve, clamped: a table of the curve over [0, 1] at 4096 steps gives the
    // same 8-bit values (the curve's slope is at most 12.92, so a step moves it by at most 0.8 of an 8-bit level)
    // without a pow per channel.
    static const std::vector<uchar> table = [] {
        std::vector<uchar> t(4097);
        for (int i = 0; i <= 4096; ++i)
            t[std::size_t(i)] = uchar(std::lround(std::clamp(srgbEncode(float(i) / 4096.0f), 0.0f, 1.0f) * 255.0f));
        return t;
    }();
    const float scale = float(std::exp2(exposure)) * 4096.0f;
    for (int y = 0; y < image.height(); ++y) {
        uchar* row = out.scanLine(y);
        for (int x = 0; x < image.width(); ++x) {
            for (int c = 0; c < 3; ++c) {
                const float v = image.at(x, y, c) * scale;
                row[4 * x + c] = table[std::size_t(v > 0.0f ? std::min(v + 0.5f, 4096.0f) : 0.0f)];
            }
            row[4 * x + 3] = 255;
        }
    }
    return out;
}

double sharedDifferenceScale(const std::vector<ViewFrame>& frames) {
    double sum = 0.0;
    long count = 0;
    // Of what the views are compared against: their references, or the image chosen as the reference (Shift+1-9;
    // the only one in an image-only session).
    for (const ViewFrame& f : frames) {
        const Image* against = f.reference ? f.reference.get() : f.alternate.get();
        if (!against) continue;
        for (int y = 0; y < against->height(); ++y)
            for (int x = 0; x < against->width(); ++x) {
                sum += luminance(*against, x, y);
                ++count;
            }
    }
    return count > 0 && sum > 0.0 ? 0.1 * sum / double(count) : 1e-3;
}

std::vector<QRect> viewRects(const std::vector<ViewFrame>& frames, const CompositorState& state, QSize size) {
    return cells(frames, state, size);
}

QImage compose(const std::vector<ViewFrame>& frames, const CompositorState& state, QSize size) {
    QImage frame(size.expandedTo(QSize(1, 1)), QImage::Format_RGBA8888);
    frame.fill(QColor(28, 28, 30));
    QPainter p(&frame);
    p.setRenderHint(QPainter::SmoothPixmapTransform, false);
    if (frames.empty()) {
        p.setPen(QColor(200, 200, 200));
        p.drawText(frame.rect(), Qt::AlignCenter, "This project has no views");
        return frame;
    }
    const std::vector<QRect> rects = cells(frames, state, size);
    const double scale =
        state.diff != DiffMode::Off && state.diff != DiffMode::Flip ? cachedDifferenceScale(frames) : 0.0;
    // The display transform in the cache's key: its name, and the config it comes from.
    const std::string transformKey =
        state.displayTransform.name() + "|" +
        std::to_string(reinterpret_cast<std::uintptr_t>(state.displayTransform.config().get()));
    auto displayFull = [&](const ViewFrame& f, bool reference) -> QImage {
        const std::shared_ptr<const Image>& img = reference ? comparand(f) : shownImage(f);
        const double exposure = f.exposure + state.exposureOffset;
        if (state.diff != DiffMode::Off && !reference) {
            // Only between images of one state: the last pair that matched while the reference catches up.
            const ComparisonPair pair = comparisonPair(f);
            const std::shared_ptr<const Image>&a = pair.image, &b = pair.against;
            if (!a || !b || a->width() != b->width() || a->height() != b->height()) return {};
            return cachedDisplay(a, b, 0.0, std::size_t(state.diff), scale, [&] {
                // FLIP's map from the comparison model when it is of this pair, else computed here.
                if (state.diff == DiffMode::Flip && f.flipMap && f.flipImage == a && f.flipAgainst == b)
                    return toDisplay(flipColourMap(*f.flipMap, a->width(), a->height()), 0.0);
                return differenceDisplay(*a, *b, state.diff, scale);
            });
        }
        if (!img) return {};
        return cachedDisplay(img, nullptr, exposure, 16 + std::hash<std::string>()(transformKey), 0.0,
                             [&] { return toDisplay(*img, exposure, state.displayTransform); });
    };
    // Every view shows the same part of its image (synchronized zoom and pan).
    auto display = [&](const ViewFrame& f, bool reference) -> QImage {
        const QImage full = displayFull(f, reference);
        if (full.isNull() || state.zoom <= 1.0) return full;
        return full.copy(visiblePart(full.size(), state).toAlignedRect());
    };
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const QRect r = rects[i];
        if (r.isEmpty()) continue;
        const ViewFrame& f = frames[i];
        if (state.layout == Layout::Split) {
            const QImage left = display(f, state.swapped), right = display(f, !state.swapped);
            const int divider = r.x() + int(std::round(state.split * r.width()));
            if (!left.isNull()) {
                const QImage scaled = left.scaled(r.size());
                p.drawImage(QRect(r.x(), r.y(), divider - r.x(), r.height()), scaled,
                            QRect(0, 0, divider - r.x(), r.height()));
            }
            if (!right.isNull()) {
                const QImage scaled = right.scaled(r.size());
                p.drawImage(QRect(divider, r.y(), r.right() + 1 - divider, r.height()), scaled,
                            QRect(divider - r.x(), 0, r.right() + 1 - divider, r.height()));
            }
            // A side without its image says why instead of staying black.
            auto notReady = [&](bool referenceSide, QRect side) {
                if (side.width() <= 0) return;
                p.setPen(QColor(200, 200, 200));
                const QString what = referenceSide ? (referenceProgress(f).isEmpty() ? comparandName(f) + " not ready"
                                                                                     : referenceProgress(f))
                                                   : (f.error.isEmpty() ? QString("rendering...") : "failed");
                p.drawText(side, Qt::AlignCenter | Qt::TextWordWrap, what);
            };
            if (left.isNull()) notReady(state.swapped, QRect(r.x(), r.y(), divider - r.x(), r.height()));
            if (right.isNull()) notReady(!state.swapped, QRect(divider, r.y(), r.right() + 1 - divider, r.height()));
            p.setPen(QPen(QColor(255, 255, 255), 1));
            p.drawLine(divider, r.y(), divider, r.bottom());
            QString other = comparandName(f);
            if (!f.snapshot && !f.alternate && f.reference && referenceStale(f)) other += " (stale)";
            const QString sides = state.swapped ? other + " | " + f.technique : f.technique + " | " + other;
            const QFontMetrics metrics(captionFont(p.font()));
            drawLabel(p, r, {fitted(metrics, r.width(), {f.name + "  -  " + sides}),
                             fitted(metrics, r.width(),
                                    {metricsLine(f), metricsLine(f, Detail::Compact), metricsLine(f, Detail::Minimal)})});
            if (f.image) drawRegion(p, r, visiblePart(QSize(f.image->width(), f.image->height()), state), state.region);
            if (f.image && !f.file)
                drawMarkers(p, r, visiblePart(QSize(f.image->width(), f.image->height()), state), state.markers);
            continue;
        }
        const bool reference = state.layout == Layout::Single && state.showReference;
        const QImage img = display(f, reference);
        if (img.isNull()) {
            p.setPen(QColor(120, 120, 120));
            p.drawRect(r.adjusted(0, 0, -1, -1));
            QString waiting = "rendering...";
            if (reference && !f.snapshot && !f.alternate && !referenceProgress(f).isEmpty())
                waiting = referenceProgress(f);
            else if (!reference && state.diff != DiffMode::Off && f.image)
                waiting = f.chosenReference            ? QString("the other views' reference")
                          : !incomparable(f).isEmpty() ? "no difference: " + incomparable(f)
                                                       : QString("difference waiting for the reference");
            p.drawText(r, Qt::AlignCenter, f.error.isEmpty() ? waiting : "failed");
        } else {
            // A reduced preview is scaled up like the full image (nearest: its pixels show), or bilinearly.
            const bool smooth = state.smoothPreviews && !reference && f.preview && shownImage(f) == f.preview;
            p.setRenderHint(QPainter::SmoothPixmapTransform, smooth);
            p.drawImage(r, img);
            p.setRenderHint(QPainter::SmoothPixmapTransform, false);
        }
        drawLabel(p, r, tileCaption(f, reference, r.width(), p.font()));
        if (f.image) drawRegion(p, r, visiblePart(QSize(f.image->width(), f.image->height()), state), state.region);
        if (f.image && !f.file && !img.isNull())
            drawMarkers(p, r, visiblePart(QSize(f.image->width(), f.image->height()), state), state.markers);
    }
    if (state.diff != DiffMode::Off) {
        drawColourBar(p, size, state.diff, scale);
    } else if (state.displayTransform.falseColour()) {
        drawFalseColourBar(p, size);
    }
    return frame;
}

}  // namespace tyndall::studio
