#!/usr/bin/env python3
"""The renderer library's layers include only what is below them (docs/architecture.md, "renderers/: the layers").

The studio has two: studio/core (the session, scheduling, comparisons, composing, exports: no widget) and
studio/ui (the window and its docks) above it. A file of studio/core includes no header of studio/ui and no Qt
Widgets header (QWidget, QDialog, QMessageBox, ...), so that the core builds, runs and is tested without a window.

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


def qt_widgets_headers():
    """The class headers of Qt Widgets (QWidget, QDialog, ...), from the installed Qt, else a list of the usual ones."""
    for base in ("/usr/include/x86_64-linux-gnu/qt6/QtWidgets", "/usr/include/aarch64-linux-gnu/qt6/QtWidgets",
                 "/usr/include/qt6/QtWidgets"):
        if pathlib.Path(base).is_dir():
            return {p.name for p in pathlib.Path(base).iterdir() if p.name.startswith("Q") and "." not in p.name}
    return {"QWidget", "QDialog", "QMessageBox", "QApplication", "QMainWindow", "QDockWidget", "QLabel",
            "QPushButton", "QProgressDialog", "QFileDialog", "QAction", "QMenu", "QToolBar", "QStatusBar"}


def check_studio(root):
    core, ui = root / "studio/core", root / "studio/ui"
    if not core.is_dir():
        return []
    ui_headers = {p.name for p in ui.glob("*.h")} if ui.is_dir() else set()
    widgets = qt_widgets_headers()
    problems = []
    for path in sorted(core.rglob("*")):
        if path.suffix not in (".h", ".cpp"):
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            target, where = m.group(1), f"{path.relative_to(root)}:{number}"
            name = target.split("/")[-1]
            if name in ui_headers:
                problems.append(f"{where}: studio/core includes {target}, a header of studio/ui (the window above it)")
            elif name in widgets or target.startswith("QtWidgets/"):
                problems.append(f"{where}: studio/core includes {target}, a Qt Widgets header; the core has no widget "
                                "(Qt Core and Gui only)")
    return problems


def self_test():
    """Copies the library's sources to a scratch folder, adds upward and sideways includes, and expects each found."""
    import shutil
    import tempfile
    with tempfile.TemporaryDirectory() as scratch:
        copy = pathlib.Path(scratch)
        for tree in ("renderers", "studio"):
            shutil.copytree(ROOT / tree, copy / tree,
                            ignore=lambda d, names: [n for n in names if pathlib.Path(d, n).is_file()
                                                     and not n.endswith((".h", ".cpp"))])
        if check(copy) or check_studio(copy):
            print("self-test: the unmodified copy already fails")
            return 1
        planted = {
            "renderers/core/src/geometry.cpp": '#include "tyndall/image/image.h"',
            "renderers/project/src/project.cpp": '#include "tyndall/techniques/registry.h"',
            "renderers/techniques/wvds/wvds.cpp": '#include "ltsd/prepared.h"',
            "studio/core/session.cpp": '#include "docks.h"',
            "studio/core/exporter.cpp": '#include <QProgressDialog>',
        }
        for name, line in planted.items():
            path = copy / name
            path.write_text(line + "\n" + path.read_text())
        found = check(copy) + check_studio(copy)
        missing = [name for name in planted if not any(p.startswith(name + ":1:") for p in found)]
        for name in missing:
            print(f"self-test: the include planted in {name} was not reported")
        print(f"self-test: {len(planted) - len(missing)} of {len(planted)} planted includes reported")
        return 1 if missing else 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    problems = check(ROOT) + check_studio(ROOT)
    for p in problems:
        print(p)
    print(f"check-layers: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
