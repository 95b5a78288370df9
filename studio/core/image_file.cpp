#include "image_file.h"

#include "tyndall/core/error.h"
#include "tyndall/image/image_io.h"

#include <QFileInfo>

namespace tyndall::studio {

namespace {
// Extensions of formats that store linear float values; every other image format stores display values.
bool linearFormat(const QString& suffix) {
    return suffix == "exr" || suffix == "hdr" || suffix == "pfm";
}
}  // namespace

bool isImageFile(const QString& path) {
    static const QStringList images = {"exr", "hdr", "pfm", "png", "jpg", "jpeg", "tif", "tiff", "bmp", "tga"};
    return images.contains(QFileInfo(path).suffix().toLower());
}

ImageFile readImageFile(const QString& path) {
    const QString suffix = QFileInfo(path).suffix().toLower();
    if (!isImageFile(path))
        throw InputError(path.toStdString() + ": not an image the studio opens (EXR, HDR, PFM, PNG, JPEG, TIFF, BMP, TGA)");
    const Image source = readImage(path.toStdString());  // InputError naming the path when missing or unreadable
    if (source.width() <= 0 || source.height() <= 0 || source.channelCount() <= 0)
        throw InputError(path.toStdString() + ": the image has no pixels");
    int channels[3] = {0, 0, 0};
    if (source.channelCount() >= 3) {
        const int r = source.channelIndex("R"), g = source.channelIndex("G"), b = source.channelIndex("B");
        if (r >= 0 && g >= 0 && b >= 0) {
            channels[0] = r, channels[1] = g, channels[2] = b;
        } else {
            channels[0] = 0, channels[1] = 1, channels[2] = 2;
        }
    } else if (source.channelCount() == 2) {
        throw InputError(path.toStdString() + ": two channels (grey and alpha?) are not an RGB image; save it as RGB");
    }
    ImageFile file;
    file.displayReferred = !linearFormat(suffix);
    auto image = std::make_shared<Image>(Image::rgb(source.width(), source.height()));
    for (int y = 0; y < source.height(); ++y)
        for (int x = 0; x < source.width(); ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = source.at(x, y, channels[c]);
                image->at(x, y, c) = file.displayReferred ? srgbDecode(v) : v;
            }
    image->metadata = source.metadata;
    image->metadata["sourceFile"] = QFileInfo(path).absoluteFilePath().toStdString();
    file.image = std::move(image);
    file.kind = suffix.toUpper() + (file.displayReferred ? " (sRGB decoded)" : "");
    return file;
}

}  // namespace tyndall::studio
