#!/usr/bin/env python3
"""Prints the navigation solution of a running rins deployment, one line per sample.

Run it next to `rins up`, with the same deployment environment (both default to the user's own):

    RINS_IPC_PREFIX=... RINS_IPC_ROOT=... python examples/python/echo_nav.py --count 10
    python examples/python/echo_nav.py --json          # one JSON object per sample

It needs the `iceoryx2` package (`python/setup-venv` makes a venv with it) and imports
`python/rins_topics.py` from this repository. Each line shows the header's sequence number, the
navigator mode and integrity, roll/pitch/yaw in degrees, latitude/longitude in degrees and the
altitude in metres. It follows both navigator lanes through the lane selector
(`rins_topics.subscribe_nav`): one sample per sequence number, whichever lane delivers.

Exit status: 0 after --count samples (or when interrupted), 2 when no deployment is found (its
configuration file is missing), 3 when nothing arrives within --timeout seconds.
"""

import argparse
import json
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
import rins_topics as rt  # noqa: E402


def euler_deg(q) -> "tuple[float, float, float]":
    """Roll, pitch, yaw (ZYX, degrees) of the body (FRD) → NED quaternion, scalar first."""
    w, x, y, z = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return math.degrees(roll), math.degrees(pitch), math.degrees(yaw)


def describe(state: "rt.NavState") -> dict:
    """The sample as a JSON-ready dict."""
    q = list(state.quaternion)
    roll, pitch, yaw = euler_deg(q)
    return {
        "seq": state.header.origin_seq,
        "version": state.version,
        "lane": state.lane,
        "mode": rt.wire_name(rt.NavMode, state.mode),
        "integrity": rt.wire_name(rt.Integrity, state.integrity),
        "quaternion": q,
        "roll_deg": roll,
        "pitch_deg": pitch,
        "yaw_deg": yaw,
        "lat_deg": math.degrees(state.latitude_rad),
        "lon_deg": math.degrees(state.longitude_rad),
        "alt_m": state.altitude_m,
    }


def line(d: dict) -> str:
    return (
        f"seq {d['seq']:>9} {d['mode']:<10} {d['integrity']:<8} "
        f"roll {d['roll_deg']:8.3f} pitch {d['pitch_deg']:8.3f} yaw {d['yaw_deg']:8.3f} deg  "
        f"lat {d['lat_deg']:12.7f} lon {d['lon_deg']:12.7f} alt {d['alt_m']:9.3f} m"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=0, help="stop after N samples (0: run on)")
    parser.add_argument("--json", action="store_true", help="one JSON object per line")
    parser.add_argument(
        "--timeout", type=float, default=10.0, help="give up after this many seconds without a sample"
    )
    args = parser.parse_args()

    import iceoryx2 as iox2

    iox2.set_log_level_from_env_or(iox2.LogLevel.Warn)
    try:
        node = rt.open_node("echo-nav-py")
        subscriber = rt.subscribe_nav(node, timeout_s=args.timeout)
    except rt.NoDeployment as e:
        print(f"echo_nav: {e}", file=sys.stderr)
        return 2
    except rt.TopicNotFound as e:
        print(f"echo_nav: {e} within {args.timeout} s", file=sys.stderr)
        return 3

    received = 0
    started = time.monotonic()
    last = started
    # Polled every few milliseconds: the subscriber queues up to SUBSCRIBER_BUFFER samples, half a
    # second of the 1 kHz stream, so nothing is lost between polls.
    pause = iox2.Duration.from_millis(5)
    try:
        while args.count == 0 or received < args.count:
            state = subscriber.receive()
            if state is None:
                if time.monotonic() - last > args.timeout:
                    print(
                        f"echo_nav: no sample on {rt.NAV_STATE} for {args.timeout} s "
                        f"({received} received)",
                        file=sys.stderr,
                    )
                    return 3
                node.wait(pause)
                continue
            received += 1
            last = time.monotonic()
            d = describe(state)
            print(json.dumps(d) if args.json else line(d), flush=True)
    except (KeyboardInterrupt, iox2.NodeWaitFailure):
        pass
    elapsed = time.monotonic() - started
    rate = received / elapsed if elapsed > 0 else 0.0
    print(f"echo_nav: {received} samples in {elapsed:.2f} s ({rate:.0f}/s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
