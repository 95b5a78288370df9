#!/usr/bin/env bash
# The Debian package end to end, as a Debian user installs it: builds it (packaging/deb.sh), checks it with lintian
# (no errors), installs it with apt-get, renders the bundled default project's reference and takes the studio's
# screenshot from the installed paths, then removes it again.
#   packaging/test-deb.sh [BUILD_DIR]
# Needs root (or sudo) to install; says so and exits 77 (skipped) without.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-$root/build}
if [ "$(id -u)" -eq 0 ]; then sudo_cmd=(); elif command -v sudo >/dev/null; then sudo_cmd=(sudo); else
    echo "test-deb: SKIPPED: installing the package needs root or sudo"; exit 77
fi
work=$(mktemp -d)
installed=0
cleanup() {
    if [ "$installed" = 1 ]; then "${sudo_cmd[@]}" apt-get remove -y -q tyndall >/dev/null || true; fi
    rm -rf "$work"
}
trap cleanup EXIT

"$root/packaging/deb.sh" "$work/out" "$build"
deb=$(ls "$work"/out/tyndall_*_amd64.deb)
echo "test-deb: $(basename "$deb"), $(du -h "$deb" | cut -f1)"
dpkg-deb --field "$deb" Package Version Architecture Depends
lintian --fail-on error "$deb" || { echo "test-deb: FAILED: lintian reports errors"; exit 1; }

DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q "$deb" >/dev/null
installed=1
for f in /usr/bin/tyndall /usr/bin/tyndall-studio /usr/bin/tyndall-plot /usr/share/tyndall/projects/default.json \
         /usr/share/tyndall/shaders /usr/share/tyndall/tables/hg.ltsd /usr/share/tyndall/colour/tyndall.ocio \
         /usr/share/applications/tyndall-studio.desktop \
         /usr/share/icons/hicolor/scalable/apps/tyndall.svg /usr/share/man/man1/tyndall.1.gz \
         /usr/share/doc/tyndall/copyright /usr/share/doc/tyndall/architecture.md; do
    [ -e "$f" ] || { echo "test-deb: FAILED: the package did not install $f"; exit 1; }
done
cd "$work"
# From the installed paths only: no TYNDALL_ROOT, not from the build folder.
env -u TYNDALL_ROOT /usr/bin/tyndall render /usr/share/tyndall/projects/default.json --reference --spp 4 --size 64x48 \
    -o x.exr
[ -s x.exr ] || { echo "test-deb: FAILED: the installed tyndall wrote no image"; exit 1; }
# PNGs through the installed OpenColorIO config's ACES view, said in the PNG's text.
env -u TYNDALL_ROOT -u OCIO /usr/bin/tyndall render /usr/share/tyndall/projects/default.json --reference --spp 4 \
    --size 64x48 --display sRGB --ocio-view "ACES 1.0 - SDR Video" -o x.png 2>ocio.err
[ ! -s ocio.err ] || { cat ocio.err; echo "test-deb: FAILED: the installed config was passed over"; exit 1; }
grep -aq "/usr/share/tyndall/colour/tyndall.ocio" x.png ||
    { echo "test-deb: FAILED: the PNG does not name the installed OpenColorIO config"; exit 1; }
env -u TYNDALL_ROOT QT_QPA_PLATFORM=xcb TYNDALL_VULKAN_VALIDATION=0 \
    xvfb-run -a -s "-screen 0 1280x800x24" /usr/bin/tyndall-studio --screenshot studio.png
[ -s studio.png ] || { echo "test-deb: FAILED: the installed studio wrote no screenshot"; exit 1; }
zcat /usr/share/man/man1/tyndall.1.gz | grep -q '^\.SS "tyndall sweep"' ||
    { echo "test-deb: FAILED: the man page does not describe the subcommands"; exit 1; }
echo "test-deb: PASSED"
