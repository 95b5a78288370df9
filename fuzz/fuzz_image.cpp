// libFuzzer target: an image file as `tyndall compare` reads it (readLinearExr for .exr, readImage as the studio opens
// any other image, then the metrics and a difference image against itself). The bytes are written to a file of this
// process (OpenEXR and libpng read files) with the extension of the first byte's choice: even .exr, odd .png.
// InputError is the expected answer; anything else escaping is a finding. Seeds include a PNG named .exr and an EXR
// with a NaN.
#include "tyndall/core/error.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("tyndall-fuzz-image-" + std::to_string(::getpid()) + (data[0] % 2 ? ".png" : ".exr")))
                                 .string();
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) return 0;
    std::fwrite(data + 1, 1, size - 1, file);
    std::fclose(file);
    try {
        const tyndall::Image image = data[0] % 2 ? tyndall::readImage(path) : tyndall::readLinearExr(path, "images");
        (void)tyndall::computeMetrics(image, image, 0.0, tyndall::Region{});
        (void)tyndall::differenceImage(image, image, tyndall::DifferenceKind::Signed, 1.0);
    } catch (const tyndall::InputError&) {
    }
    std::remove(path.c_str());
    return 0;
}
