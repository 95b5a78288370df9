// Images from other programs as studio views (tev-like): EXR, Radiance HDR, PFM and other float formats are read as
// linear RGB; 8- and 16-bit formats (PNG, JPEG, TIFF, ...) hold display values, so they are decoded with the sRGB
// curve (tonemap.h's sRGB display transform inverted; values the display clipped stay at 1). A single channel is
// repeated into R, G and B; otherwise the channels named R, G, B, else the first three. Any other channels and the
// alpha are dropped.
#pragma once

#include "tyndall/image/image.h"

#include <QString>

#include <memory>

namespace tyndall::studio {

struct ImageFile {
    std::shared_ptr<const Image> image;  // linear RGB
    QString kind;                        // "EXR", "PNG (sRGB decoded)", ...
    bool displayReferred = false;        // decoded from display values: comparisons are approximate
};

// Throws InputError naming the file: missing, unreadable, or not an image.
ImageFile readImageFile(const QString& path);

// Whether `path` names an image the studio opens as a view (by its extension), rather than a project.
bool isImageFile(const QString& path);

}  // namespace tyndall::studio
