// Reading and writing images: EXR through OpenEXR (all float channels and the metadata) and PNG through libpng
// (exposure, then the display transform, 8 bits). The library needs nothing more, so that the CLI, the GPU tests and
// the bundle (packaging/bundle.sh) carry no OpenImageIO; the studio opens other formats through it
// (studio/core/image_file.h).
#pragma once

#include "tyndall/image/colour_management.h"
#include "tyndall/image/image.h"

#include <cstdint>
#include <string>

namespace tyndall {

// Writes by extension (.exr or .png), all or nothing (writeFileAtomically, output.h). Throws InputError naming the path
// for what the caller asked wrongly (extension, missing folder, a PNG without R, G, B), OutputError when the
// environment refuses (disk full, read-only folder).
// PNG: RGB only, multiplied by 2^exposure, through the display transform (an OpenColorIO display and view, or one of
// Tyndall's operators, colour_management.h), 8 bits, with the image's metadata and the display transform and exposure
// as text chunks ("tyndall:display", "tyndall:view", "tyndall:ocioConfig" or "tyndall:tonemap";
// "tyndall:displayExposure").
void writeImage(const Image& image, const std::string& path, double exposure = 0.0,
                const DisplayTransform& display = {});
// The bytes of the file writeImage would write, the format chosen by `path`'s extension; for OutputSet::stage when
// several outputs must appear together.
std::string encodeImage(const Image& image, const std::string& path, double exposure = 0.0,
                        const DisplayTransform& display = {});

// Reads an OpenEXR file (the data window of its first part; every channel as float, every string metadata attribute)
// or a PNG (stored values / 255; channels Y, Y A, R G B or R G B A; the text chunks Tyndall wrote as metadata), told
// apart by their first bytes. Throws InputError naming the path for a missing, unreadable, damaged or other file.
Image readImage(const std::string& path);

// What readImage accepts, for any reader: an image header decides how much memory is allocated, so it is bounded to
// 2^28 values (pixels x channels) and 64 channels. Throws InputError naming the path for an empty or larger image.
void checkReadableImageSize(const std::string& path, std::int64_t width, std::int64_t height, std::int64_t channels);

// An input of metrics (`tyndall compare`, `probe`): an OpenEXR image by name and by content, every value finite. An
// InputError names the path, `field` (the option that gave it) and what is allowed.
Image readLinearExr(const std::string& path, const std::string& field);

// Linear -> display: 2^exposure, then the sRGB transfer function, clamped to [0, 1].
float srgbEncode(float linear);
float tonemap(float linear, double exposure);

// Display -> linear: the inverse of srgbEncode on [0, 1] (used to store colour maps given as sRGB values).
float srgbDecode(float encoded);

}  // namespace tyndall
