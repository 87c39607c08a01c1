"""Decodes every message of a rins recording the way Foxglove's Python libraries do.

Usage: check_mcap.py FILE.mcap

Prints a JSON object {"topics": {topic: {"count": n, "first": {...}}}} where "first" holds a few
fields of the topic's first message (navigation solutions and the health report), named by their
path ("header.origin_seq", "services[0].pid"). Exits non-zero if any message fails to decode.
"""

import json
import math
import sys

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

# Fields reported from the first message of a topic, by schema name.
FIELDS = {
    "rins/msg/NavState": [
        "quaternion",
        "header.origin_seq",
        "velocity_ned_mps",
        "mode",
        "lane",
        "integrity_reasons",
        "aiding_rejected",
    ],
    "rins/msg/FusedImu": ["header.stage_pub_ns", "gyro_test_statistic"],
    "rins/msg/RawImu": ["gyro_counts", "temperature_c"],
    "rins/msg/HealthReport": ["count", "services[0].pid", "link.crc_errors"],
}


def lookup(message, path):
    """The value at a dotted path with optional [index] parts."""
    value = message
    for part in path.split("."):
        index = None
        if part.endswith("]"):
            part, index = part[:-1].split("[")
        value = getattr(value, part)
        if index is not None:
            value = value[int(index)]
    return plain(value)


def plain(value):
    """A JSON-friendly copy: sequences as lists, NaN as null."""
    if isinstance(value, (bytes, bytearray)):
        return list(value)
    if isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
        return [plain(v) for v in list(value)]
    if isinstance(value, float) and math.isnan(value):
        return None
    return value


def main():
    if len(sys.argv) != 2:
        print("usage: check_mcap.py FILE.mcap", file=sys.stderr)
        return 2
    topics = {}
    with open(sys.argv[1], "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, _message, decoded in reader.iter_decoded_messages():
            entry = topics.setdefault(channel.topic, {"count": 0})
            entry["count"] += 1
            if entry["count"] == 1:
                entry["schema"] = schema.name if schema else None
                fields = FIELDS.get(schema.name if schema else "", [])
                entry["first"] = {path: lookup(decoded, path) for path in fields}
    print(json.dumps({"topics": topics}, indent=1, sort_keys=True))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Exception as error:  # any decode error fails the check, with its reason
        print(f"check_mcap: {type(error).__name__}: {error}", file=sys.stderr)
        sys.exit(1)
