#!/usr/bin/env python3
"""The renderer library's layers include only what is below them (docs/architecture.md, "renderers/: the layers").

Each layer is a folder renderers/<layer>/ whose public headers are include/tyndall/<layer>/. A file of a layer may
include the headers of the layers it lists below, and no others; a technique's folder (renderers/techniques/<name>/)
may include only its own "<name>/..." headers of all the technique folders, and only the registry
(renderers/techniques/registry/) includes every technique's. Run as a test (Architecture.Layers);
exit 1 with every offending include, file and line."""
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
LAYERS = {
    "core": {"core"},
    "gpu": {"gpu", "core"},
    "image": {"image", "core"},
    "tables": {"tables", "core"},
    "project": {"project", "core"},
    "framework": {"framework", "core", "gpu", "image"},
    "techniques": {"techniques", "framework", "project", "tables", "image", "gpu", "core"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]')


def check(root):
    TECHNIQUES = sorted(p.name for p in (root / "renderers/techniques").iterdir()
                        if p.is_dir() and p.name not in ("include", "registry"))
    problems = []
    for layer, allowed in LAYERS.items():
        base = root / "renderers" / layer
        for path in sorted(base.rglob("*")):
            if path.suffix not in (".h", ".cpp") or "/test/" in str(path.relative_to(root)):
                continue
            own_technique, registry = None, False
            if layer == "techniques":
                parts = path.relative_to(base).parts
                own_technique = parts[0] if parts[0] in TECHNIQUES else None
                registry = parts[0] == "registry"
            for number, line in enumerate(path.read_text().splitlines(), 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                target = m.group(1)
                where = f"{path.relative_to(root)}:{number}"
                if target.startswith("tyndall/"):
                    area = target.split("/")[1]
                    if area not in allowed:
                        problems.append(f"{where}: the {layer} layer includes {target} (a layer above it, or beside "
                                        f"it; it may include: {', '.join(sorted(allowed))})")
                first = target.split("/")[0]
                if first in TECHNIQUES and first != own_technique and not registry:
                    problems.append(f"{where}: includes {target}, a header of the technique '{first}'; only the "
                                    "registry knows every technique, and a technique includes only its own headers")
    if layer_folders := sorted(p.name for p in (root / "renderers").iterdir()
                               if (p / "include/tyndall" / p.name).is_dir() and p.name not in LAYERS):
        problems.append(f"renderers/{layer_folders[0]}: a layer that tools/check-layers.py does not know")
    return problems


def self_test():
    """Copies the library's sources to a scratch folder, adds upward and sideways includes, and expects each found."""
    import shutil
    import tempfile
    with tempfile.TemporaryDirectory() as scratch:
        copy = pathlib.Path(scratch)
        shutil.copytree(ROOT / "renderers", copy / "renderers",
                        ignore=lambda d, names: [n for n in names if pathlib.Path(d, n).is_file()
                                                 and not n.endswith((".h", ".cpp"))])
        if check(copy):
            print("self-test: the unmodified copy already fails")
            return 1
        planted = {
            "renderers/core/src/geometry.cpp": '#include "tyndall/image/image.h"',
            "renderers/project/src/project.cpp": '#include "tyndall/techniques/registry.h"',
            "renderers/techniques/wvds/wvds.cpp": '#include "ltsd/prepared.h"',
        }
        for name, line in planted.items():
            path = copy / name
            path.write_text(line + "\n" + path.read_text())
        found = check(copy)
        missing = [name for name in planted if not any(p.startswith(name + ":1:") for p in found)]
        for name in missing:
            print(f"self-test: the include planted in {name} was not reported")
        print(f"self-test: {len(planted) - len(missing)} of {len(planted)} planted includes reported")
        return 1 if missing else 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    problems = check(ROOT)
    for p in problems:
        print(p)
    print(f"check-layers: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
