#!/usr/bin/env bash
# The relocatable bundle on a machine that has nothing but a kernel and a Vulkan driver (docs/gpu.md): builds it
# (packaging/bundle.sh), unpacks it into an empty root, and runs it there with chroot, so that no file of this
# machine's /usr or /lib can be reached. The root holds the bundle, a static busybox as /bin/sh (any Linux has a
# shell), /dev/null, /proc and /tmp, and, for the second half only, "the driver": lavapipe's manifest and its
# libraries under /driver, as a GPU machine has its own. Checks:
#   1. without a driver: `tyndall info` exits 1 with one line saying so; a CPU reference render works; gpu-check.sh
#      writes a report that says no device was found, and exits 1;
#   2. with the driver: `tyndall info` finds llvmpipe, and with LD_DEBUG=libs every library the dynamic loader
#      opened is the bundle's (lib/) or the driver's (/driver); a GPU view renders; gpu-check.sh runs one GPU test
#      executable (validation on) and the frame-time benchmark at a small size, and reports "pass".
#   packaging/test-bundle.sh [BUILD_DIR]
# Needs root for chroot (exits 77, skipped, without), and busybox-static.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
if [ "$(id -u)" -ne 0 ]; then echo "test-bundle: SKIPPED: chroot needs root"; exit 77; fi
busybox=$(command -v busybox || true)
if [ -z "$busybox" ] || ldd "$busybox" >/dev/null 2>&1; then
    echo "test-bundle: FAILED: needs a static busybox (the busybox-static package)"; exit 1
fi
work=$(mktemp -d)
jail=$work/root
cleanup() {
    umount "$jail/proc" 2>/dev/null || true
    rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "test-bundle: FAILED: $*"; exit 1; }

"$root/packaging/bundle.sh" "$work/out" "$build"
archive=$(ls "$work"/out/tyndall-bundle-*-x86_64.tar.xz)
echo "test-bundle: $(basename "$archive"), $(du -h "$archive" | cut -f1)"

# The empty root: the bundle, busybox, /dev/null, /proc, /tmp. Nothing else.
mkdir -p "$jail"/{bin,dev,proc,tmp,opt}
chmod 1777 "$jail/tmp"
tar -C "$jail/opt" -xJf "$archive"
bundle=/opt/$(basename "$archive" .tar.xz)
cp "$busybox" "$jail/bin/busybox"
for tool in sh cat sed grep awk head tr date uname mktemp dirname basename readlink rm mkdir ls; do
    ln -s busybox "$jail/bin/$tool"
done
touch "$jail/dev/null"
mount --bind /dev/null "$jail/dev/null"
mount -t proc proc "$jail/proc"
cleanup() {
    umount "$jail/proc" 2>/dev/null || true
    umount "$jail/dev/null" 2>/dev/null || true
    rm -rf "$work"
}
in_jail() { chroot "$jail" /bin/env -i PATH=/bin HOME=/tmp TMPDIR=/tmp "$@"; }
ln -s busybox "$jail/bin/env"

# 1. Without a driver.
set +e
in_jail "$bundle/bin/tyndall" info >"$work/info.out" 2>"$work/info.err"
status=$?
set -e
[ "$status" = 1 ] || fail "tyndall info without a driver exited $status, not 1"
[ "$(wc -l <"$work/info.err")" = 1 ] || { cat "$work/info.err"; fail "tyndall info without a driver: not one line"; }
grep -q "no Vulkan device" "$work/info.err" || fail "tyndall info without a driver: $(cat "$work/info.err")"
grep -q "^  ltsd - LTSD" "$work/info.out" || fail "tyndall info without a driver listed no techniques"
grep -q "^Colour (OpenColorIO, PNG output): the shipped config .*/share/tyndall/colour/tyndall.ocio$" \
    "$work/info.out" || fail "tyndall info does not take the bundle's OpenColorIO config: $(grep Colour "$work/info.out")"
echo "test-bundle: without a driver: $(cat "$work/info.err")"
in_jail "$bundle/bin/tyndall" render "$bundle/share/tyndall/projects/default.json" --reference --spp 2 \
    --size 32x24 -o /tmp/reference.exr >/dev/null
[ -s "$jail/tmp/reference.exr" ] || fail "the CPU reference render wrote nothing"
set +e
in_jail "$bundle/gpu-check.sh" --out /tmp/nodevice >"$work/nodevice.log" 2>&1
status=$?
set -e
[ "$status" = 1 ] || { cat "$work/nodevice.log"; fail "gpu-check.sh without a driver exited $status, not 1"; }
python3 - "$jail/tmp/nodevice/gpu-report.json" <<'EOF' || fail "gpu-check.sh without a driver: the report"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["verdict"] == "no device", r["verdict"]
assert "no Vulkan device" in r["problems"][0] or r["noDevice"], r
EOF
grep -q "Verdict: no device" "$jail/tmp/nodevice/gpu-report.md" || fail "gpu-report.md without a driver"

# 2. With the driver: lavapipe's library and every library it needs, under /driver, with a manifest naming it there.
lvp=$(sed -n 's/.*"library_path"[[:space:]]*:[[:space:]]*"\([^"]*\)".*/\1/p' /usr/share/vulkan/icd.d/lvp_icd.x86_64.json)
mkdir -p "$jail/driver/lib"
cp -L "$lvp" "$jail/driver/lib/"
ldd "$lvp" | awk '/=> \// { print $3 }' | while read -r library; do cp -L "$library" "$jail/driver/lib/"; done
sed "s|\"library_path\": *\"[^\"]*\"|\"library_path\": \"/driver/lib/$(basename "$lvp")\"|" \
    /usr/share/vulkan/icd.d/lvp_icd.x86_64.json >"$jail/driver/lvp_icd.json"
with_driver() { in_jail VK_DRIVER_FILES=/driver/lvp_icd.json TYNDALL_DRIVER_LIBRARY_PATH=/driver/lib "$@"; }

with_driver LD_DEBUG=libs "$bundle/bin/tyndall" info >"$work/info.out" 2>"$work/libs.log" ||
    { tail -5 "$work/libs.log"; fail "tyndall info with lavapipe failed"; }
grep -q "llvmpipe" "$work/info.out" || fail "tyndall info with lavapipe found no llvmpipe device"
# Every library the loader opened ("calling init: PATH"): the bundle's or the driver's.
grep -o 'calling init: [^ ]*' "$work/libs.log" | sed 's/calling init: //' | sort -u >"$work/opened"
[ -s "$work/opened" ] || fail "LD_DEBUG=libs listed no library"
if grep -v -e "^$bundle/lib/" -e "^/driver/lib/" "$work/opened"; then
    fail "the libraries above came neither from the bundle nor from the driver"
fi
echo "test-bundle: with lavapipe: $(grep -c "^$bundle/lib/" "$work/opened") libraries from the bundle," \
    "$(grep -c '^/driver/lib/' "$work/opened") from the driver, none from elsewhere"

with_driver "$bundle/bin/tyndall" render "$bundle/share/tyndall/projects/examples/wvds-box.json" --view analytic \
    --set 'views[analytic].parameters.device=gpu' --spp 1 --size 32x24 -o /tmp/wvds.exr >/dev/null
[ -s "$jail/tmp/wvds.exr" ] || fail "the GPU view render wrote nothing"

with_driver "$bundle/gpu-check.sh" --out /tmp/check --only 'tyndall_gpu_tests=GpuValidation.*:GpuContext.*:VisibilityTest.*' \
    --bench-sizes 48x32 --bench-frames 3 --bench-filter 'BM_Frame/(wvds|pegoraro|volume-ris)/' >"$work/check.log" 2>&1 ||
    { cat "$work/check.log"; cat "$jail/tmp/check/gpu-report.md" 2>/dev/null; fail "gpu-check.sh with lavapipe"; }
python3 - "$jail/tmp/check/gpu-report.json" <<'EOF' || fail "gpu-check.sh with lavapipe: the report"
import json, sys
r = json.load(open(sys.argv[1]))
assert r["verdict"] == "pass", r["problems"]
assert "llvmpipe" in r["device"]["name"], r["device"]
assert r["tests"]["passed"] >= 5 and r["tests"]["failed"] == 0, r["tests"]
cases = {c["case"] for c in r["frames"]["cases"]}
assert cases == {"wvds", "pegoraro", "volume-ris"}, cases
for c in r["frames"]["cases"]:
    assert c["gpuMs"] > 0 and c["frames"] == 3 and "error" not in c, c
print("test-bundle: gpu-check with lavapipe: %d tests passed, frame times %s" % (
    r["tests"]["passed"], ", ".join("%s %.1f ms" % (c["case"], c["gpuMs"]) for c in r["frames"]["cases"])))
EOF
grep -q "Verdict: pass" "$jail/tmp/check/gpu-report.md" || fail "gpu-report.md with lavapipe"
echo "test-bundle: passed"
