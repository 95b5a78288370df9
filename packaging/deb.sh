#!/usr/bin/env bash
# Builds the Debian package of Tyndall: OUT_DIR/tyndall_<version>_amd64.deb, from a build folder (default: build/,
# configured and built here if needed), through cpack -G DEB: the binaries stripped, installed under /usr with the
# shaders, tables, projects and docs, the desktop entry, icon, MIME type and the CLI's man page; its dependencies
# computed from the binaries (dpkg-shlibdeps).
#   packaging/deb.sh OUT_DIR [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${1:?usage: packaging/deb.sh OUT_DIR [BUILD_DIR]}
build=${2:-$root/build}
mkdir -p "$out"
out=$(cd "$out" && pwd)
"$root/packaging/configure-build.sh" "$build"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$build" && cpack -G DEB -B "$work" >"$work/cpack.log" 2>&1) || { cat "$work/cpack.log" >&2; exit 1; }
deb=$(find "$work" -maxdepth 1 -name 'tyndall_*_amd64.deb' | head -n 1)
[ -n "$deb" ] || { echo "deb.sh: cpack wrote no tyndall_*_amd64.deb" >&2; cat "$work/cpack.log" >&2; exit 1; }
mv "$deb" "$out/"
echo "wrote $out/$(basename "$deb")"
