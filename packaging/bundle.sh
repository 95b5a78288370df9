#!/usr/bin/env bash
# Builds the relocatable bundle of Tyndall: OUT_DIR/tyndall-bundle-<version>-x86_64.tar.xz (at most 60 MiB), which
# unpacks into one folder that runs on any x86-64 Linux, whatever its distribution and C library, with nothing
# installed: the `tyndall` CLI, the GPU test executables, the GPU benchmarks, the shaders, tables and bundled
# projects, the Vulkan loader and validation layer, and every shared library they need down to the C library and its
# dynamic loader, which the launchers (bin/tyndall, bin/tyndall-exec) run them through. Only the kernel and the GPU
# driver come from the machine. gpu-check.sh at its top runs the GPU check (docs/gpu.md).
#   packaging/bundle.sh OUT_DIR [BUILD_DIR]
# BUILD_DIR (default build/) is configured and built here if needed.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:?usage: packaging/bundle.sh OUT_DIR [BUILD_DIR]}
build=${2:-$root/build}
mkdir -p "$out"
out=$(cd "$out" && pwd)
"$root/packaging/configure-build.sh" "$build"

version=$(sed -n 's/^project(Tyndall VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
name=tyndall-bundle-$version-x86_64
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
stage=$work/$name
mkdir -p "$stage"/{bin,lib,libexec/tests/spirv,libexec/bench,share/vulkan/explicit_layer.d}

# The programs, stripped of their debug information (they are 5 to 8 times smaller).
program() {  # program BUILD_RELATIVE_PATH LIBEXEC_FOLDER
    local file=$build/$1
    [ -x "$file" ] || { echo "bundle.sh: $file was not built" >&2; exit 1; }
    strip --strip-unneeded -o "$stage/libexec/$2/$(basename "$file")" "$file"
}
program studio/cli/tyndall .
program tools/gpu-check/tyndall-gpu-check .
for test in renderers/gpu/tyndall_gpu_tests renderers/framework/test/tyndall_framework_tests \
    tests/tyndall_primary_hits_tests renderers/techniques/ltsd/test/tyndall_ltsd_tests \
    renderers/techniques/isv/test/tyndall_isv_tests renderers/techniques/wvds/test/tyndall_wvds_tests \
    renderers/techniques/volume_ris/test/tyndall_volume_ris_tests \
    renderers/techniques/pegoraro/test/tyndall_pegoraro_technique_tests; do
    program "$test" tests
done
cp "$build"/renderers/gpu/test_spirv/*.spv "$stage/libexec/tests/spirv/"
program renderers/bench/tyndall_gpu_frames_bench bench
program renderers/bench/tyndall_gpu_bench bench

# The data, as the Debian package installs it (cmake --install), and what the tests read from the source tree.
cmake --install "$build" --prefix "$work/install" >/dev/null
cp -r "$work/install/share/tyndall" "$stage/share/tyndall"
# The tests run with share/tyndall-tests as their resource root (and source tree): the shaders with the test ones,
# the tables and projects of share/tyndall, and the GLSL files of the GPU tests.
tests=$stage/share/tyndall-tests
mkdir -p "$tests/renderers/gpu/test"
cp -r "$root/shaders" "$tests/shaders"
rm -f "$tests/shaders/CMakeLists.txt"
ln -s ../tyndall/projects "$tests/projects"
ln -s ../tyndall/tables "$tests/tables"
cp "$root"/renderers/gpu/test/*.glsl "$tests/renderers/gpu/test/"

# The Khronos validation layer (gpu-check runs the tests with it), its manifest pointing beside itself.
layer=$(find /usr/lib/x86_64-linux-gnu -maxdepth 1 -name libVkLayer_khronos_validation.so | head -n 1)
[ -n "$layer" ] || { echo "bundle.sh: the Vulkan validation layer is not installed (vulkan-validationlayers)" >&2; exit 1; }
cp "$layer" "$stage/lib/"
sed 's|"library_path": *"[^"]*"|"library_path": "../../../lib/libVkLayer_khronos_validation.so"|' \
    /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json \
    >"$stage/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json"

# Every shared library the programs and the layer need, as this machine resolves them, the C library and its loader
# included; nothing of the GPU driver (the Vulkan loader finds that on the machine).
elves=$(find "$stage/libexec" "$stage/lib" -type f -perm -u+x -o -type f -name '*.so*')
for elf in $elves; do
    ldd "$elf" | awk '/=> \// { print $3 } /^\t\/.*ld-linux/ { print $1 }'
done | sort -u >"$work/libraries"
while read -r library; do
    target=$stage/lib/$(basename "$library")
    [ -e "$target" ] || cp -L "$library" "$target"
done <"$work/libraries"
[ -f "$stage/lib/ld-linux-x86-64.so.2" ] || { echo "bundle.sh: no dynamic loader among the libraries" >&2; exit 1; }
chmod 755 "$stage/lib/ld-linux-x86-64.so.2"

# The launchers, the check and what to read first.
install -m 755 "$root/packaging/bundle/tyndall-exec" "$root/packaging/bundle/tyndall" "$stage/bin/"
install -m 755 "$root/packaging/bundle/gpu-check.sh" "$stage/"
cp "$work/install/share/doc/tyndall/copyright" "$stage/COPYRIGHT"
cat >"$stage/README" <<EOF
Tyndall $version, a relocatable bundle for x86-64 Linux (any distribution; nothing to install).

  bin/tyndall info                     the devices, techniques and their parameters
  bin/tyndall render share/tyndall/projects/default.json --view NAME -o out.exr
  ./gpu-check.sh --out report          the GPU check: every GPU test and the frame times (docs/gpu.md)
  bin/tyndall-exec tests/PROGRAM ...   any program under libexec/, through the bundle's loader

Everything runs through the bundle's own dynamic loader (lib/ld-linux-x86-64.so.2) and libraries; only the kernel
and the Vulkan driver come from the machine. gpu-check.sh finds the driver (VK_DRIVER_FILES, the loader's folders,
/usr/local/nvidia/share/vulkan/icd.d) and adds its folder to the library path.
EOF

archive=$out/$name.tar.xz
tar -C "$work" --owner=0 --group=0 --numeric-owner -cf - "$name" | xz -9e -T "$(nproc)" >"$archive.partial"
mv "$archive.partial" "$archive"
size=$(stat -c %s "$archive")
limit=$((60 * 1024 * 1024))
if [ "$size" -gt "$limit" ]; then
    echo "bundle.sh: $archive is $((size / 1048576)) MiB, over the 60 MiB limit" >&2
    rm -f "$archive"
    exit 1
fi
echo "wrote $archive ($((size / 1048576)) MiB; unpacked $(du -sm "$stage" | cut -f1) MiB)"
