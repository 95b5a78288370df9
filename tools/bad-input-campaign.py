#!/usr/bin/env python3
"""A bad-input campaign against the tyndall CLI, simple to rerun (issues 21 and 34).

Mutates the bundled projects (one number, string or array at a time, set to an extreme or malformed value), then for
each mutant runs `tyndall validate` and, when it validates, `tyndall render` of every view at a tiny size. It reports
what the rules of docs/conventions.md ("Exit codes, outputs and limits") forbid:

  crash          a signal (segfault, abort) or an exit code other than 0, 1 and 2
  hang           no answer within the time limit
  contract       "contract violated" printed (a broken internal contract, a bug)
  validate-only  validate accepted what render then refused or failed (exit 1 or 2)
  no-file        a refusal (exit 2) whose message does not name the project file
  partial        a failed render that left its output file behind

Usage: tools/bad-input-campaign.py [--cli build/studio/cli/tyndall] [--mutants 200] [--seed 1] [--keep DIR]
Every finding is printed with the mutation that caused it; --keep writes the mutants that found something to DIR as
repro files (add them to tests/data and a test, and so to the project fuzzer's seeds). Exit status: 1 if anything was
found. A few hundred mutants take some minutes on two cores.
"""

import argparse
import copy
import json
import os
import pathlib
import random
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXTREMES = [0, -0.0, -1, 1e-308, 1e308, -1e308, 1e-12, 1e12, 0.9999999, -0.9999999, 2**63, 2**64 - 1, -(2**31),
            "abc", "", None, True, [], {}, [1e308, 1e308, 1e308], [0, 0, 0], [1e-308, 1e-308, 1e-308]]


def paths(value, prefix=()):
    """Every (path, leaf) in a JSON value; arrays of numbers count as leaves too."""
    if isinstance(value, dict):
        for key, child in value.items():
            yield from paths(child, prefix + (key,))
    elif isinstance(value, list):
        if value and all(isinstance(x, (int, float)) for x in value):
            yield prefix, value
        for i, child in enumerate(value):
            yield from paths(child, prefix + (i,))
    else:
        yield prefix, value


def mutate(project, rng):
    target_path, _ = rng.choice(list(paths(project)))
    if not target_path:
        return None, None
    mutant = copy.deepcopy(project)
    node = mutant
    for key in target_path[:-1]:
        node = node[key]
    value = rng.choice(EXTREMES)
    node[target_path[-1]] = value
    return mutant, "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in target_path).lstrip(".") + \
        " = " + json.dumps(value)


def run(cli, args, timeout):
    try:
        done = subprocess.run([cli] + args, capture_output=True, text=True, timeout=timeout)
        return done.returncode, done.stdout + done.stderr
    except subprocess.TimeoutExpired:
        return None, ""


def shrink(project):
    """Tiny images, few samples: the campaign looks for refusals, not pictures."""
    camera = project.get("camera")
    if isinstance(camera, dict):
        camera["width"], camera["height"] = 24, 16
    reference = project.get("reference")
    if isinstance(reference, dict):
        reference["spp"] = 1
    return project


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cli", default=str(ROOT / "build/studio/cli/tyndall"))
    parser.add_argument("--mutants", type=int, default=200)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=120.0)
    parser.add_argument("--keep", help="folder for the mutants that found something")
    args = parser.parse_args()

    rng = random.Random(args.seed)
    sources = sorted(p for p in (ROOT / "projects").rglob("*.json"))
    findings = []
    refused = renders = 0
    with tempfile.TemporaryDirectory(prefix="tyndall-campaign-") as scratch:
        for n in range(args.mutants):
            source = rng.choice(sources)
            mutant, what = mutate(shrink(json.loads(source.read_text())), rng)
            if mutant is None:
                continue
            name = f"mutant-{n:04d}.json"
            path = os.path.join(scratch, name)
            with open(path, "w") as f:
                json.dump(mutant, f)
            label = f"{source.relative_to(ROOT)}: {what}"

            def report(kind, detail):
                findings.append((kind, label, detail.strip()[:300]))
                print(f"{kind:14} {label}\n               {detail.strip()[:300]}", flush=True)
                if args.keep:
                    os.makedirs(args.keep, exist_ok=True)
                    with open(os.path.join(args.keep, f"{kind}-{name}"), "w") as f:
                        json.dump(mutant, f, indent=1)

            def check(code, output, command):
                if code is None:
                    report("hang", command)
                elif code not in (0, 1, 2):
                    report("crash", f"{command}: exit {code}: {output}")
                elif "contract violated" in output:
                    report("contract", f"{command}: {output}")
                elif code == 2 and name not in output:
                    report("no-file", f"{command}: {output}")

            code, output = run(args.cli, ["validate", path], args.timeout)
            check(code, output, "validate")
            if code != 0:
                refused += 1
                continue
            for view in [v.get("name") for v in mutant.get("views", []) if isinstance(v, dict)]:
                out = os.path.join(scratch, "out.exr")
                code, output = run(args.cli, ["render", path, "--view", str(view), "--spp", "1", "-o", out],
                                   args.timeout)
                renders += 1
                check(code, output, f"render --view {view}")
                if code in (1, 2) and "cancelled" not in output:
                    report("validate-only", f"render --view {view}: exit {code}: {output}")
                if code != 0 and os.path.exists(out):
                    report("partial", f"render --view {view} left {out}")
                if os.path.exists(out):
                    os.remove(out)
    print(f"{args.mutants} mutants: {refused} refused by validate, {renders} renders of the others; "
          f"{len(findings)} findings")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
