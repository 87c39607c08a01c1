"""Checks that `rins_topics` resolves a deployment's default prefix and root as rins does: the cases
come as JSON in the first argument (from tests/python_ctypes.rs), each a uid, an XDG_RUNTIME_DIR
(or null) and Rust's prefix and root. Prints `N cases match`, or every difference and exits 1."""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import rins_topics  # noqa: E402


def main() -> int:
    cases = json.loads(sys.argv[1])
    found = []
    for c in cases:
        prefix = rins_topics.default_prefix(c["uid"])
        root = rins_topics.default_root(c["uid"], c["xdg"])
        if (prefix, root) != (c["prefix"], c["root"]):
            found.append(f"{c}: Python gives prefix {prefix!r}, root {root!r}")
    for d in found:
        print(d)
    if found:
        return 1
    print(f"{len(cases)} cases match")
    return 0


if __name__ == "__main__":
    sys.exit(main())
