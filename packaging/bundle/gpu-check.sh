#!/bin/sh
# The GPU check of an unpacked Tyndall bundle (docs/gpu.md): finds the Vulkan driver, then runs tyndall-gpu-check,
# which asks `tyndall info` for the device, runs every GPU test executable of the bundle with validation and
# synchronisation validation on, runs the frame-time benchmark of every GPU technique at 512 x 512 and 1920 x 1080,
# and writes DIR/gpu-report.json and DIR/gpu-report.md (logs under DIR/logs).
#   ./gpu-check.sh --out DIR [--only EXECUTABLE[=FILTER] ...] [--bench-sizes 64x64] [--bench-filter REGEX] ...
# (./gpu-check.sh --help lists every option.) Exit status 0 when every test passed, 1 otherwise or without a device.
#
# The driver: the files in $VK_DRIVER_FILES (or $VK_ICD_FILENAMES) when set; else every driver file in the Vulkan
# loader's folders and in those GPU containers use (/usr/local/nvidia/share/vulkan/icd.d ...). Each file's library is
# looked for where the loader would (an absolute path; a path beside the file; a bare name in the machine's library
# folders and $LD_LIBRARY_PATH), and its folder joins the bundle's library path after the bundle's own libraries.
# POSIX sh and the commands of busybox only: it runs on any Linux.
set -eu
self=$(readlink -f "$0" 2>/dev/null || echo "$0")
here=$(cd "$(dirname "$self")" && pwd -P)

json_string() {  # a JSON string of $1
    printf '"%s"' "$(printf '%s' "$1" | sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' | tr '\n\t' '  ')"
}

driver_files=${VK_DRIVER_FILES:-${VK_ICD_FILENAMES:-}}
driver_origin=environment
if [ -z "$driver_files" ]; then
    driver_origin=search
    for dir in /usr/local/nvidia/share/vulkan/icd.d /usr/local/share/vulkan/icd.d /usr/share/vulkan/icd.d \
        /etc/vulkan/icd.d /usr/local/etc/vulkan/icd.d \
        "${XDG_DATA_HOME:-${HOME:-/nonexistent}/.local/share}/vulkan/icd.d"; do
        for file in "$dir"/*.json; do
            [ -f "$file" ] || continue
            case ":$driver_files:" in *":$file:"*) continue ;; esac
            driver_files=$driver_files${driver_files:+:}$file
        done
    done
fi

library_folders="/usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /lib/x86_64-linux-gnu
/usr/lib64 /lib64 /usr/lib /lib $(printf '%s' "${LD_LIBRARY_PATH:-}" | tr ':' ' ')"
driver_path=
drivers_json=
old_ifs=$IFS
IFS=:
for file in $driver_files; do
    IFS=$old_ifs
    library=$(sed -n 's/.*"library_path"[[:space:]]*:[[:space:]]*"\([^"]*\)".*/\1/p' "$file" 2>/dev/null | head -n 1)
    found=
    case $library in
        "") ;;
        /*) [ -e "$library" ] && found=$library ;;
        */*) [ -e "$(dirname "$file")/$library" ] && found=$(dirname "$file")/$library ;;
        *)
            for folder in $library_folders; do
                if [ -e "$folder/$library" ]; then
                    found=$folder/$library
                    break
                fi
            done
            ;;
    esac
    if [ -n "$found" ]; then
        folder=$(cd "$(dirname "$found")" && pwd -P)
        case ":$driver_path:" in *":$folder:"*) ;; *) driver_path=$driver_path${driver_path:+:}$folder ;; esac
    fi
    drivers_json="$drivers_json${drivers_json:+, }{\"file\": $(json_string "$file"), \"library\": $(json_string "$library"), \"found\": $(json_string "${found:-not found}")}"
    IFS=:
done
IFS=$old_ifs

if [ -n "$driver_files" ]; then
    VK_DRIVER_FILES=$driver_files
    export VK_DRIVER_FILES
fi
TYNDALL_DRIVER_LIBRARY_PATH=$driver_path
export TYNDALL_DRIVER_LIBRARY_PATH

environment=$(mktemp "${TMPDIR:-/tmp}/tyndall-gpu-check.XXXXXX")
trap 'rm -f "$environment"' EXIT
cat >"$environment" <<JSON
{
  "date": $(json_string "$(date -u +%Y-%m-%dT%H:%M:%SZ)"),
  "host": $(json_string "$(uname -n), $(uname -s) $(uname -r) $(uname -m)"),
  "driverFiles": $(json_string "${driver_files:-none found}"),
  "driverFilesFrom": $(json_string "$driver_origin"),
  "drivers": [$drivers_json],
  "libraryPath": $(json_string "$here/lib${driver_path:+:$driver_path}${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}")
}
JSON
echo "gpu-check: driver files: ${driver_files:-none found}; their libraries in: ${driver_path:-(none found)}" >&2
status=0
"$here/bin/tyndall-exec" tyndall-gpu-check --bundle "$here" --environment "$environment" "$@" || status=$?
exit $status
