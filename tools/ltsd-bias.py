#!/usr/bin/env python3
"""The LTSD technique's image bias against the reference on the bundled LTSD projects, for each S method (issue 32):
every LTSD view of projects/ltsd/*.json and projects/examples/ltsd-room.json at N = 8 (or the view's own N with
--own-nodes), with sMethod = paper and = accurate, each against the reference of the view's part of the scene at high
spp. Prints a Markdown table (energy bias in % of the reference's energy, relMSE, and the reference's own noise as a
relMSE, which bounds what a bias measurement can resolve) and writes the metrics as JSON.

  tools/ltsd-bias.py --tyndall build/studio/cli/tyndall OUT_DIR [--size 128x96] [--spp 4096] [--threads 0]

The references are kept in OUT_DIR and reused when present (same size and spp), so a second run only renders LTSD."""
import argparse
import json
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
METHODS = ["paper", "accurate"]


def ltsd_views():
    files = sorted((ROOT / "projects" / "ltsd").glob("*.json")) + [ROOT / "projects" / "examples" / "ltsd-room.json"]
    for f in files:
        project = json.loads(f.read_text())
        for view in project["views"]:
            if view.get("technique") == "ltsd":
                yield f, view


def slug(text):
    return re.sub(r"[^A-Za-z0-9]+", "-", text).strip("-")


def run(cmd):
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"failed ({done.returncode}): {' '.join(cmd)}\n{done.stderr}")
    return done.stdout


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", type=pathlib.Path)
    parser.add_argument("--tyndall", default=str(ROOT / "build" / "studio" / "cli" / "tyndall"))
    parser.add_argument("--size", default="128x96")
    parser.add_argument("--spp", type=int, default=4096, help="the reference's samples per pixel")
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--own-nodes", action="store_true", help="keep each view's N instead of N = 8")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    common = ["--size", args.size, "--threads", str(args.threads)]
    rows = []
    measured = set()
    for project, view in ltsd_views():
        name = view["name"]
        # Views that differ only in N are one measurement at N = 8 (fig10-nodes).
        parameters = {k: v for k, v in view.get("parameters", {}).items() if k != "nodes" or args.own_nodes}
        key = (project, json.dumps(parameters, sort_keys=True), json.dumps(view.get("lights")),
               json.dumps(view.get("media")))
        if key in measured:
            continue
        measured.add(key)
        stem = f"{project.stem}-{slug(name)}"
        reference = args.out / f"{stem}-reference-{args.size}-{args.spp}.exr"
        if not reference.exists():
            run([args.tyndall, "render", str(project), "--view", name, "--reference", "--spp", str(args.spp),
                 "--seed", "7", "-o", str(reference)] + common)
        nodes = view.get("parameters", {}).get("nodes", 8) if args.own_nodes else 8
        row = {"project": str(project.relative_to(ROOT)), "view": name, "nodes": nodes}
        for method in METHODS:
            image = args.out / f"{stem}-{method}.exr"
            run([args.tyndall, "render", str(project), "--view", name, "-o", str(image),
                 "--set", f"views[{name}].parameters.nodes={nodes}",
                 "--set", f"views[{name}].parameters.sMethod={method}"] + common)
            metrics = args.out / f"{stem}-{method}.json"
            run([args.tyndall, "compare", "-r", str(reference), str(image), "--json", str(metrics)])
            row[method] = json.loads(metrics.read_text())["images"][0]
        rows.append(row)
        p, a = row["paper"], row["accurate"]
        print(f"{row['project']} [{name}] N {nodes}: paper {p['energyBias']:+.2f} % relMSE {p['relMSE']:.2e}; "
              f"accurate {a['energyBias']:+.2f} % relMSE {a['relMSE']:.2e}", file=sys.stderr, flush=True)
    (args.out / "ltsd-bias.json").write_text(json.dumps(rows, indent=1))
    print(f"| project | view | N | paper's S: energy bias | relMSE | accurate S: energy bias | relMSE | "
          f"reference noise (relMSE) |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        p, a = r["paper"], r["accurate"]
        noise = a.get("referenceNoiseRelMSE")
        print(f"| {r['project']} | {r['view']} | {r['nodes']} | {p['energyBias']:+.2f} % | {p['relMSE']:.2e} | "
              f"{a['energyBias']:+.2f} % | {a['relMSE']:.2e} | {noise:.1e} |" if noise is not None else
              f"| {r['project']} | {r['view']} | {r['nodes']} | {p['energyBias']:+.2f} % | {p['relMSE']:.2e} | "
              f"{a['energyBias']:+.2f} % | {a['relMSE']:.2e} | - |")


if __name__ == "__main__":
    main()
