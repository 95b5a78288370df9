#!/usr/bin/env bash
# Installs the dependencies, builds Tyndall and opens the bundled default project (or the project given) in the
# studio. Without a display (no $DISPLAY) it renders the project's reference headless instead and says where it is.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="${TYNDALL_BUILD_DIR:-$root/build}"
project="${1:-$root/projects/default.json}"

"$root/packaging/install-deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$build" -j "$(nproc)" --target tyndall tyndall-studio

if [ -n "${DISPLAY:-}" ]; then
  # QVulkanWindow needs the xcb platform (Wayland sessions run it through XWayland).
  exec env QT_QPA_PLATFORM="${QT_QPA_PLATFORM:-xcb}" "$build/studio/app/tyndall-studio" "$project"
fi

echo "No display: rendering the reference of $project headless instead of opening the studio."
out="$root/out"
mkdir -p "$out"
stem=$(basename "$project" .json)
"$build/studio/cli/tyndall" render "$project" --reference -o "$out/$stem-reference.exr" -o "$out/$stem-reference.png"
echo "The reference of $project is in $out/$stem-reference.png (and .exr with variance and metadata)."
