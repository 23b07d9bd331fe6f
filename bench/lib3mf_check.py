#!/usr/bin/env python3
"""Check 3MF files with lib3mf, the 3MF Consortium's reference implementation.

Usage: python3 bench/lib3mf_check.py FILE.3mf [FILE.3mf ...]

Each file is read with lib3mf in strict mode (when the installed lib3mf offers it), then
every reader warning is printed, followed by a one-line summary with the object, build item
and triangle counts. The exit status is 0 when every file reads without error or warning,
1 when any file has an error or warning, 2 when lib3mf is not installed (`pip install lib3mf`).

conduit's writer (`conduit_3mf::write`) is expected to pass this check with no warnings.
"""

import sys


def load_wrapper():
    try:
        import lib3mf
    except ImportError:
        print("lib3mf is not installed: pip install lib3mf", file=sys.stderr)
        sys.exit(2)
    if hasattr(lib3mf, "get_wrapper"):
        return lib3mf, lib3mf.get_wrapper()
    return lib3mf, lib3mf.Wrapper()


def count_triangles(model):
    total = 0
    it = model.GetMeshObjects()
    while it.MoveNext():
        total += it.GetCurrentMeshObject().GetTriangleCount()
    return total


def check(lib3mf, wrapper, path):
    """Returns the number of problems (errors + warnings) found in one file."""
    model = wrapper.CreateModel()
    reader = model.QueryReader("3mf")
    strict = False
    if hasattr(reader, "SetStrictModeActive"):
        reader.SetStrictModeActive(True)
        strict = reader.GetStrictModeActive()
    try:
        reader.ReadFromFile(path)
    except lib3mf.ELib3MFException as e:
        print(f"{path}: ERROR (strict={strict}): {e}")
        return 1
    problems = 0
    for i in range(reader.GetWarningCount()):
        message, code = reader.GetWarning(i)
        print(f"{path}: WARNING {code}: {message}")
        problems += 1
    objects = 0
    it = model.GetObjects()
    while it.MoveNext():
        objects += 1
    items = 0
    bit = model.GetBuildItems()
    while bit.MoveNext():
        items += 1
    status = "OK" if problems == 0 else f"{problems} warning(s)"
    print(
        f"{path}: {status} (strict={strict}, unit={model.GetUnit()}, objects={objects}, "
        f"build items={items}, triangles={count_triangles(model)})"
    )
    return problems


def main(argv):
    if len(argv) < 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    lib3mf, wrapper = load_wrapper()
    major, minor, micro = wrapper.GetLibraryVersion()
    print(f"lib3mf {major}.{minor}.{micro}")
    bad = 0
    for path in argv[1:]:
        if check(lib3mf, wrapper, path):
            bad += 1
    print(f"{len(argv) - 1 - bad} passed, {bad} failed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
