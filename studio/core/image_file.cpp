#include "image_file.h"

#include "tyndall/core/error.h"
#include "tyndall/image/image_io.h"

#include <OpenImageIO/imageio.h>

#include <QFileInfo>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tyndall::studio {

namespace {

// The formats beyond the library's EXR and PNG (HDR, PFM, JPEG, TIFF, BMP, TGA), through OpenImageIO: the first
// subimage, every channel as float, bounded as the library's reader is.
Image readOtherFormat(const std::string& path) {
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
    const auto failed = [&](const std::string& local) {
        const std::string global = OIIO::geterror();
        const std::string reason = !local.empty() ? local : !global.empty() ? global : "unknown OpenImageIO error";
        return InputError(InputLocation{.file = path}, "cannot read image: " + reason);
    };
    if (!in) throw failed("");
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.deep || spec.depth > 1)
        throw InputError(InputLocation{.file = path}, "cannot read image: deep or volume images are not supported");
    checkReadableImageSize(path, spec.width, spec.height, spec.nchannels);
    std::vector<std::string> names;
    for (int c = 0; c < spec.nchannels; ++c) {
        std::string name = c < int(spec.channelnames.size()) ? spec.channelnames[std::size_t(c)] : "";
        if (name.empty() || std::find(names.begin(), names.end(), name) != names.end())
            name = "channel" + std::to_string(c);
        names.push_back(name);
    }
    Image image(spec.width, spec.height, names);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.data())) throw failed(in->geterror());
    return image;
}

// Extensions of formats that store linear float values; every other image format stores display values.
bool linearFormat(const QString& suffix) {
    return suffix == "exr" || suffix == "hdr" || suffix == "pfm";
}
}  // namespace

bool isImageFile(const QString& path) {
    static const QStringList images = {"exr", "hdr", "pfm", "png", "jpg", "jpeg", "tif", "tiff", "bmp", "tga"};
    return images.contains(QFileInfo(path).suffix().toLower());
}

ImageFile readImageFile(const QString& path, const ColourConfig* config) {
    const QString suffix = QFileInfo(path).suffix().toLower();
    if (!isImageFile(path))
        throw InputError(path.toStdString() + ": not an image the studio opens (EXR, HDR, PFM, PNG, JPEG, TIFF, BMP, TGA)");
    // InputError naming the path when missing or unreadable.
    const Image source =
        suffix == "exr" || suffix == "png" ? readImage(path.toStdString()) : readOtherFormat(path.toStdString());
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
    // The file's colour space: its own attribute (EXR) when the config knows it, else the config's file rules.
    std::string space;
    for (const char* key : {"colorSpace", "colorspace", "oiio:ColorSpace"})
        if (auto it = source.metadata.find(key); config && space.empty() && it != source.metadata.end())
            if (config->hasColourSpace(it->second)) space = it->second;
    if (config && space.empty()) space = config->colourSpaceOfFile(path.toStdString());
    file.displayReferred = space.empty() ? !linearFormat(suffix) : space != config->sceneLinear();
    auto image = std::make_shared<Image>(Image::rgb(source.width(), source.height()));
    for (int y = 0; y < source.height(); ++y)
        for (int x = 0; x < source.width(); ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = source.at(x, y, channels[c]);
                image->at(x, y, c) = space.empty() && file.displayReferred ? srgbDecode(v) : v;
            }
    if (!space.empty()) config->toSceneLinear(*image, space);  // InputError naming the space
    image->metadata = source.metadata;
    image->metadata["sourceFile"] = QFileInfo(path).absoluteFilePath().toStdString();
    file.image = std::move(image);
    file.kind = suffix.toUpper() + (!space.empty() && space != config->sceneLinear()
                                        ? " (" + QString::fromStdString(space) + ")"
                                    : space.empty() && file.displayReferred ? QString(" (sRGB decoded)")
                                                                            : QString());
    return file;
}

}  // namespace tyndall::studio
