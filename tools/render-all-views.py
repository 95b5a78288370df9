#!/usr/bin/env python3
"""Render every view (and the reference of each) of every bundled project at a small size and low spp, or compare two
such folders pixel for pixel. Used to prove that a refactoring changes no image (issue 30): render with the old build,
render with the new one, compare.

  tools/render-all-views.py render --tyndall build/studio/cli/tyndall OUT_DIR [--size 48x36] [--spp 2] [--gpu]
  tools/render-all-views.py compare OLD_DIR NEW_DIR

compare reads the EXRs with oiiotool and requires every channel of every pixel to be equal (a difference of 0); the
metadata (render times) is not compared. Exit 0: identical; 1: a difference or a file missing on one side.

--gpu renders the views of every technique with a GPU and a CPU path on the GPU instead (device=gpu; on lavapipe where
there is no other): "auto" picks the CPU on lavapipe, so without it those paths are not compared. The shaders are read
from the source tree at run time: render the old build with the old shaders checked out."""
import argparse
import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


GPU_TECHNIQUES = {"isv", "ltsd", "pegoraro", "volume-ris", "wvds"}  # those with a device parameter


def projects():
    return sorted(p for p in (ROOT / "projects").rglob("*.json"))


def render(args):
    out = pathlib.Path(args.out)
    failures = 0
    for project in projects():
        views = json.loads(project.read_text()).get("views", [])
        rel = project.relative_to(ROOT / "projects").with_suffix("")
        if args.gpu:
            jobs = [(f"views-gpu/{v['name']}", ["--view", v["name"], "--set", f"views[{v['name']}].parameters.device=gpu"],
                     v["name"]) for v in views if v.get("technique") in GPU_TECHNIQUES]
        else:
            # Views under views/ (a view may be named "reference"), the project's reference beside them.
            jobs = [(f"views/{v['name']}", ["--view", v["name"]], v["name"]) for v in views] + \
                   [("reference", ["--reference"], "(reference)")]
        for name, flags, label in jobs:
            target = out / rel / f"{name}.exr"
            target.parent.mkdir(parents=True, exist_ok=True)
            cmd = [args.tyndall, "render", str(project), *flags, "--size", args.size, "--spp", str(args.spp),
                   "--threads", "2", "-o", str(target)]
            r = subprocess.run(cmd, capture_output=True, text=True)
            status = "ok" if r.returncode == 0 else f"exit {r.returncode}"
            print(f"{rel}: {label}: {status}", flush=True)
            if r.returncode != 0:
                failures += 1
                (out / rel / f"{name}.error.txt").write_text(r.stderr)
    return 0 if failures == 0 else 1


def compare(args):
    old, new = pathlib.Path(args.old), pathlib.Path(args.new)
    names = sorted({p.relative_to(old) for p in old.rglob("*.exr")} | {p.relative_to(new) for p in new.rglob("*.exr")})
    errors = {p.relative_to(old) for p in old.rglob("*.error.txt")} | {p.relative_to(new) for p in new.rglob("*.error.txt")}
    bad = 0
    for name in names:
        a, b = old / name, new / name
        if not a.exists() or not b.exists():
            print(f"{name}: only in {'new' if not a.exists() else 'old'}")
            bad += 1
            continue
        r = subprocess.run(["oiiotool", "--fail", "0", "--failpercent", "0", "--warn", "0", str(a), str(b), "--diff"],
                           capture_output=True, text=True)
        same = r.returncode == 0 and "PASS" in r.stdout
        if not same:
            bad += 1
            print(f"{name}: DIFFERENT\n{r.stdout}{r.stderr}")
    for name in sorted(errors):
        ta = (old / name).read_text() if (old / name).exists() else None
        tb = (new / name).read_text() if (new / name).exists() else None
        if ta != tb:
            bad += 1
            print(f"{name}: the error messages differ:\n  old: {ta}\n  new: {tb}")
    print(f"{len(names)} images, {len(errors)} refusals compared: {bad} differ")
    return 0 if bad == 0 else 1


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render")
    r.add_argument("out")
    r.add_argument("--tyndall", required=True)
    r.add_argument("--size", default="48x36")
    r.add_argument("--spp", type=int, default=2)
    r.add_argument("--gpu", action="store_true", help="the GPU paths (device=gpu) of the techniques that have one")
    c = sub.add_parser("compare")
    c.add_argument("old")
    c.add_argument("new")
    args = parser.parse_args()
    return render(args) if args.command == "render" else compare(args)


if __name__ == "__main__":
    sys.exit(main())
