"""Follows the navigation stream of a running deployment through `rins_topics.subscribe_nav` (both
lanes, merged by the lane selector) until its standard input closes, for tests/python_topics.rs.

Prints one JSON line per sample, `{"seq": N, "lane": L, "selected": S, "trusted": T}` (the lane
that published it, the lane selected after it, and whether the lane selector trusts it), then a
summary line `{"summary": {...}}`: samples received, first and last sequence number, sequence
numbers missing from the output, split into those a lane delivered to this process (`lost`: the
selector dropped them) and those neither lane did (`holes`: absent from the input), samples per
lane, holes filled, lane switches by cause and the last one. Exit status 2 when the deployment or
its topic is missing."""

import dataclasses
import json
import select
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import lane_selector  # noqa: E402
import rins_topics as rt  # noqa: E402


def stdin_closed() -> bool:
    """The test closed our standard input: time to stop."""
    readable, _, _ = select.select([sys.stdin], [], [], 0)
    return bool(readable) and sys.stdin.readline() == ""


def main() -> int:
    try:
        node = rt.open_node("follow-nav-py")
        nav = rt.subscribe_nav(node, timeout_s=30)
    except (rt.NoDeployment, rt.TopicNotFound) as e:
        print(f"follow_nav: {e}", file=sys.stderr)
        return 2
    # Every sequence number either lane delivered to this process.
    published = set()
    take = nav.selector.push

    def push(lane, state):
        published.add(state.header.origin_seq)
        take(lane, state)

    nav.selector.push = push
    settle = nav.selector.config.settle
    received, first, last, missing, gaps = 0, None, None, 0, []
    checked = time.monotonic()
    while True:
        # Standard input is looked at every 50 ms, samples or not.
        if time.monotonic() - checked >= 0.05:
            sys.stdout.flush()
            if stdin_closed():
                break
            checked = time.monotonic()
        state = nav.receive(timeout_s=0.05)
        if state is None:
            continue
        seq = state.header.origin_seq
        if last is not None:
            assert seq > last, f"seq {seq} after {last}"
            missing += seq - last - 1
            gaps.extend(range(last + 1, seq))
        first = seq if first is None else first
        last = seq
        received += 1
        trusted = lane_selector.trusted(state, settle)
        line = {"seq": seq, "lane": state.lane, "selected": nav.selected_lane, "trusted": trusted}
        print(json.dumps(line))
    switch = nav.selector.last_switch
    summary = {
        "received": received,
        "first_seq": first,
        "last_seq": last,
        "missing": missing,
        "lost": [seq for seq in gaps if seq in published],
        "holes": [seq for seq in gaps if seq not in published][:100],
        "skipped": nav.skipped,
        "lane_totals": nav.lane_totals,
        "filled": nav.selector.filled,
        "switches": nav.selector.switches,
        "switch_counts": nav.selector.switch_counts,
        "last_switch": dataclasses.asdict(switch) if switch is not None else None,
        "last_switch_text": str(switch) if switch is not None else None,
    }
    print(json.dumps({"summary": summary}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
