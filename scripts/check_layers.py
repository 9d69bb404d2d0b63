#!/usr/bin/env python3
"""The library's dependency direction (docs/ARCHITECTURE.md), checked over #include lines.

Each folder of src/nipdem may include only itself and the folders listed for it; a folder
not listed here is an error too (a new folder must say where it stands). Run by ctest
(`layering`); usage: check_layers.py REPO_ROOT.
"""
import pathlib
import re
import sys

ALLOWED = {
    "core": set(),
    "geometry": {"core"},
    "models": {"core"},
    "solvers": {"core"},
    "engine": {"core", "geometry", "models", "solvers"},
    "io": {"core", "models", "engine"},
    "nip": {"core", "geometry", "models", "solvers", "engine", "io"},
    "analysis": {"core", "io"},
    "experiments": {"core", "geometry", "models", "solvers", "engine", "io", "nip", "analysis"},
}
GENERATED = {"version.hpp", "embedded_clusters.hpp", "embedded_preset_black.hpp", "embedded_preset_color.hpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"nipdem/([^"]+)"', re.M)


def main(root: pathlib.Path) -> int:
    lib = root / "src" / "nipdem"
    errors = []
    for f in sorted(lib.rglob("*")):
        if f.suffix not in (".hpp", ".cpp", ".h"):
            continue
        rel = f.relative_to(lib)
        if len(rel.parts) < 2:
            continue
        layer = rel.parts[0]
        if layer not in ALLOWED:
            errors.append(f"src/nipdem/{rel}: folder '{layer}' has no place in the layering (scripts/check_layers.py)")
            continue
        for m in INCLUDE.finditer(f.read_text(encoding="utf-8", errors="replace")):
            target = m.group(1)
            if target in GENERATED:
                continue
            dep = target.split("/")[0]
            if dep != layer and dep not in ALLOWED[layer]:
                errors.append(f"src/nipdem/{rel}: includes nipdem/{target}: {layer} must not depend on {dep}")
    for e in errors:
        print(e)
    if errors:
        print(f"{len(errors)} include(s) against the dependency direction of docs/ARCHITECTURE.md")
        return 1
    print("layering: every include points down the dependency direction")
    return 0


def self_test() -> int:
    """The check must fail on an upward include and on an unlisted folder, and pass a clean tree."""
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        lib = pathlib.Path(d) / "src" / "nipdem"
        (lib / "models").mkdir(parents=True)
        (lib / "engine").mkdir()
        (lib / "engine" / "sim.hpp").write_text('#include "nipdem/models/law.hpp"\n')
        (lib / "models" / "law.hpp").write_text('#include "nipdem/core/vec2.hpp"\n')
        if main(pathlib.Path(d)) != 0:
            return 1
        (lib / "models" / "law.hpp").write_text('#include "nipdem/engine/sim.hpp"\n')
        if main(pathlib.Path(d)) != 1:
            return 1
        (lib / "models" / "law.hpp").write_text("\n")
        (lib / "misc").mkdir()
        (lib / "misc" / "x.hpp").write_text("\n")
        if main(pathlib.Path(d)) != 1:
            return 1
    print("self-test: upward include and unlisted folder caught")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--self-test":
        sys.exit(self_test())
    sys.exit(main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")))
