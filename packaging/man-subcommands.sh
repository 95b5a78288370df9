#!/usr/bin/env bash
# Writes a help2man include file with every subcommand's --help, so that the man page documents their options too.
#   packaging/man-subcommands.sh TYNDALL > subcommands.h2m
set -euo pipefail
tyndall=$1
echo "[SUBCOMMANDS IN DETAIL]"
for sub in render merge sweep validate compare probe info tables plot; do
    echo ".SS \"tyndall $sub\""
    echo ".nf"
    # roff: a backslash is \e; a line starting with . or ' would be a request.
    "$tyndall" "$sub" --help | sed -e "s|$tyndall|tyndall|g" -e 's/\\/\\e/g' -e "s/^\([.']\)/\\\\\&\1/"
    echo ".fi"
done
