"""Checks that `ctypes` lays out every structure of `rins_topics` as Rust does: the layouts come as
JSON in the first argument (from tests/python_ctypes.rs), each a name, type name, size, alignment and
fields with offset and size. Prints `N structures match`, or every difference and exits 1."""

import ctypes
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import rins_topics  # noqa: E402


def differences(layout: dict) -> "list[str]":
    name = layout["name"]
    cls = getattr(rins_topics, name, None)
    if cls is None:
        return [f"{name}: no such structure in rins_topics"]
    found = []
    if cls.type_name() != layout["type_name"]:
        found.append(f"{name}: type_name {cls.type_name()!r}, Rust {layout['type_name']!r}")
    if ctypes.sizeof(cls) != layout["size"]:
        found.append(f"{name}: size {ctypes.sizeof(cls)}, Rust {layout['size']}")
    if ctypes.alignment(cls) != layout["align"]:
        found.append(f"{name}: alignment {ctypes.alignment(cls)}, Rust {layout['align']}")
    names = [f[0] for f in cls._fields_]
    if names != [f["name"] for f in layout["fields"]]:
        found.append(f"{name}: fields {names}, Rust {[f['name'] for f in layout['fields']]}")
    for field in layout["fields"]:
        descriptor = getattr(cls, field["name"], None)
        if descriptor is None:
            continue
        if (descriptor.offset, descriptor.size) != (field["offset"], field["size"]):
            found.append(
                f"{name}.{field['name']}: offset {descriptor.offset} size {descriptor.size}, "
                f"Rust offset {field['offset']} size {field['size']}"
            )
    return found


def main() -> int:
    layouts = json.loads(sys.argv[1])
    found = [d for layout in layouts for d in differences(layout)]
    for d in found:
        print(d)
    if found:
        return 1
    print(f"{len(layouts)} structures match")
    return 0


if __name__ == "__main__":
    sys.exit(main())
