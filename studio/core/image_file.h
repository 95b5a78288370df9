// Images from other programs as studio views (tev-like), converted to the linear Rec.709 of renders. The colour space
// of a file comes from the OpenColorIO config (colour_management.h): an EXR's own "colorSpace" attribute when the
// config has that space, else the config's file rules (the shipped config's: PNG, JPEG, TIFF, BMP and TGA are sRGB,
// the rest linear). Without a config that says (OpenColorIO's raw config), 8- and 16-bit formats are decoded with the
// sRGB curve (tonemap.h's sRGB display transform inverted) and float formats taken as linear. Values a display
// clipped stay at 1. A single channel is repeated into R, G and B; otherwise the channels named R, G, B, else the
// first three. Any other channels and the alpha are dropped.
#pragma once

#include "tyndall/image/colour_management.h"
#include "tyndall/image/image.h"

#include <QString>

#include <memory>

namespace tyndall::studio {

struct ImageFile {
    std::shared_ptr<const Image> image;  // linear RGB
    QString kind;                        // "EXR", "PNG (sRGB - Texture)", ...
    bool displayReferred = false;        // decoded from display values: comparisons are approximate
};

// Throws InputError naming the file: missing, unreadable, or not an image. `config`: whose colour spaces (null: the
// hand-written sRGB decoding).
ImageFile readImageFile(const QString& path, const ColourConfig* config = nullptr);

// Whether `path` names an image the studio opens as a view (by its extension), rather than a project.
bool isImageFile(const QString& path);

}  // namespace tyndall::studio
