"""Checks the Python lane selector (`python/lane_selector.py`) against the rule of the Rust one: the
same cases as the Rust unit tests, on `rins_topics.NavState` samples built here (no iceoryx2, no
deployment). The first argument, when given, is the Rust defaults as JSON (from
tests/python_topics.rs), which the Python defaults must equal. Prints `N cases pass`; a failing
case raises AssertionError (exit status 1)."""

import dataclasses
import json
import sys
from collections import deque
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
import lane_selector as ls  # noqa: E402
import rins_topics as rt  # noqa: E402

SETTLE = 100
MS = 1_000_000
NAVIGATING = int(rt.NavMode.NAVIGATING)
ALIGNING = int(rt.NavMode.ALIGNING)


def cfg() -> ls.SelectorConfig:
    return ls.SelectorConfig(
        switch_lag=8,
        dead_after_ns=8_000_000,
        dead_after_untrusted_ns=100_000_000,
        settle=SETTLE,
        min_dwell=50,
    )


def nav(lane: int, seq: int, start: int, ns: int = 0, mode: int = NAVIGATING) -> rt.NavState:
    """A solution of `lane` at `seq` that started at `start`, published at `ns` (0: unstamped)."""
    s = rt.NavState()
    s.mode = mode
    s.lane = lane
    s.solution_start_seq = start
    s.quaternion[0] = 1.0
    s.header.origin_seq = seq
    s.header.stage_pub_ns[ls.NAVIGATOR_STAGE] = ns
    return s


def aligning(lane: int, seq: int) -> rt.NavState:
    return nav(lane, seq, 0, mode=ALIGNING)


def stamped(lane: int, seq: int, ns: int) -> rt.NavState:
    return nav(lane, seq, 1, ns)


def drain(sel: ls.LaneSelector, out: list) -> None:
    while (s := sel.pop()) is not None:
        out.append((s.header.origin_seq, s.lane))


def seqs(out: list) -> list:
    return [o[0] for o in out]


def only_a_settled_usable_mode_is_trusted():
    settled = nav(0, 1 + SETTLE, 1)
    assert ls.trusted(settled, SETTLE)
    settled.mode = int(rt.NavMode.COASTING)
    assert ls.trusted(settled, SETTLE)
    for mode in (ALIGNING, int(rt.NavMode.INVALID), 4, 255):
        settled.mode = mode
        assert not ls.trusted(settled, SETTLE), mode
    assert not ls.trusted(nav(0, SETTLE, 1), SETTLE)
    # Each reason is named.
    s = nav(0, 1 + SETTLE, 1)
    assert ls.distrust(s, SETTLE) is None
    assert ls.distrust(aligning(0, 500), SETTLE) == ls.DISTRUST_ALIGNING
    assert ls.distrust(nav(0, 500, 1, mode=int(rt.NavMode.INVALID)), SETTLE) == ls.DISTRUST_INVALID
    assert ls.distrust(nav(0, 130, 100), SETTLE) == ls.DISTRUST_YOUNG
    assert ls.distrust(nav(0, 130, 0), SETTLE) == ls.DISTRUST_YOUNG
    s.quaternion[2] = float("nan")
    assert ls.distrust(s, SETTLE) == ls.DISTRUST_NON_FINITE


def healthy_lanes_deliver_the_selected_lane_once_in_order():
    sel, out = ls.LaneSelector(cfg()), []
    for seq in range(1, 1001):
        # The standby is sometimes first: its samples are never taken while lane 0 is healthy.
        sel.push(1, nav(1, seq, 1))
        sel.push(0, nav(0, seq, 1))
        drain(sel, out)
    assert out == [(seq, 0) for seq in range(1, 1001)]
    assert sel.switches == 0


def a_killed_lane_loses_no_sample_and_the_gap_is_the_switch_lag():
    sel, out, stall = ls.LaneSelector(cfg()), [], 0
    for seq in range(1, 501):
        sel.push(1, nav(1, seq, 1))
        if seq <= 200:
            sel.push(0, nav(0, seq, 1))
        before = len(out)
        drain(sel, out)
        stall += len(out) == before
    assert seqs(out) == list(range(1, 501))
    # Lane 1 has to be `switch_lag` ahead of the output (200): 207 arrives without output, 208
    # switches.
    assert stall == 7, stall
    assert sel.last_switch == ls.Switch(0, 1, ls.BEHIND, 201, ahead=8), sel.last_switch
    assert all(lane == 1 for _, lane in out[200:])


def a_late_sample_is_not_a_failure():
    sel, out = ls.LaneSelector(cfg()), []
    for seq in range(1, 301):
        sel.push(1, nav(1, seq, 1))
        # Lane 0 delivers 100..=106 late, in one burst after lane 1's 106.
        if not 100 <= seq <= 106:
            if seq == 107:
                for late in range(100, 107):
                    sel.push(0, nav(0, late, 1))
            sel.push(0, nav(0, seq, 1))
        drain(sel, out)
    assert sel.switches == 0
    assert len(out) == 300 and all(lane == 0 for _, lane in out)


def a_burst_with_the_other_lane_ahead_is_not_a_dead_lane():
    sel, out = ls.LaneSelector(cfg()), []
    for seq in range(1, 101):
        sel.push(0, stamped(0, seq, seq * MS))
        sel.push(1, stamped(1, seq, seq * MS))
        drain(sel, out)
    # A replayed history: 300 samples within 0.3 ms, lane 1 working through 40 at a time before
    # lane 0 catches up.
    t0 = 101 * MS
    burst = list(range(101, 401))
    for i in range(0, len(burst), 40):
        chunk = burst[i : i + 40]
        for seq in chunk:
            sel.push(1, stamped(1, seq, t0 + seq * 1_000))
        drain(sel, out)
        for seq in chunk:
            sel.push(0, stamped(0, seq, t0 + seq * 1_000 + 500))
        drain(sel, out)
    assert sel.switches == 0
    assert out == [(seq, 0) for seq in range(1, 401)]


def a_silent_lane_is_left_after_the_dead_time():
    sel, out, stall = ls.LaneSelector(cfg()), [], 0
    for seq in range(1, 301):
        sel.push(1, stamped(1, seq, seq * MS))
        if seq <= 200:
            sel.push(0, stamped(0, seq, seq * MS))
        before = len(out)
        drain(sel, out)
        stall += len(out) == before
    # Lane 1 publishes 209 at 209 ms, 8 ms after its 201, the first sample lane 0 owed: the
    # switch.
    assert stall == 8, stall
    assert sel.last_switch == ls.Switch(0, 1, ls.SILENT, 201, ahead=9, silent_ns=8 * MS)
    assert len(out) == 300


def a_starved_lane_is_not_left_for_one_that_just_reset():
    sel, out = ls.LaneSelector(cfg()), []

    def young(seq: int, ns: int) -> rt.NavState:
        # Lane 1 restarted at 701: not trusted until its solution has run SETTLE samples.
        return nav(1, seq, 701, ns)

    for seq in range(1, 701):
        sel.push(0, stamped(0, seq, seq * MS))
        drain(sel, out)
    # Lane 0 starved of CPU for 50 ms while lane 1 publishes 701..=750, then catches up.
    for seq in range(701, 751):
        sel.push(1, young(seq, seq * MS))
        drain(sel, out)
    for seq in range(701, 761):
        sel.push(0, stamped(0, seq, 751 * MS + seq))
        drain(sel, out)
    assert sel.switches == 0
    assert len(out) == 760 and all(lane == 0 for _, lane in out)
    # Lane 0 silent for good: after 100 ms lane 1 takes over, young as it is, from the next sample.
    for seq in range(761, 881):
        sel.push(1, young(seq, seq * MS))
        drain(sel, out)
    assert (sel.last_switch.to_lane, sel.last_switch.at_seq) == (1, 761)
    assert seqs(out) == list(range(1, 881))


def consume(sel: ls.LaneSelector, lanes: list, now: int, out: list) -> None:
    """A consumer's pass: takes each lane's samples published by `now` while its ring has room,
    then delivers what is due on its clock."""
    while True:
        pulled = False
        for lane, queue in enumerate(lanes):
            if sel.has_room(lane) and queue and ls.published_ns(queue[0]) <= now:
                sel.push(lane, queue.popleft())
                pulled = True
        while (s := sel.pop(now)) is not None:
            out.append((s.header.origin_seq, s.lane))
        if not pulled:
            return


def a_burst_that_fills_the_ring_waits_for_the_dead_time_and_loses_nothing():
    sel, out, lanes = ls.LaneSelector(cfg()), [], [deque(), deque()]
    for seq in range(1, 101):
        for lane, queue in enumerate(lanes):
            queue.append(stamped(lane, seq, seq * MS))
    # The input stops for 300 ms, then 1000 samples arrive at once: lane 1 works through them
    # within 1 ms at 400 ms, lane 0 (waiting for a CPU) 5 ms later.
    for seq in range(101, 1101):
        lanes[1].append(stamped(1, seq, 400 * MS + seq * 1_000))
    for seq in range(101, 1101):
        lanes[0].append(stamped(0, seq, 405 * MS + seq * 1_000))
    for ms in range(1, 421):
        consume(sel, lanes, ms * MS, out)
    assert (sel.switches, sel.overwritten) == (0, 0)
    assert all(lane == 0 for _, lane in out)
    # Lane 0 is gone; lane 1 delivers another burst of 1000 at 500 ms. Its ring fills within a
    # millisecond and the rest waits in its queue: the switch comes when lane 0 has been silent
    # for the dead time on the consumer's clock, from the first sample it owed.
    for seq in range(1101, 2101):
        lanes[1].append(stamped(1, seq, 500 * MS + (seq - 1100) * 500))
    switched_at = None
    for ms in range(421, 601):
        consume(sel, lanes, ms * MS, out)
        if switched_at is None and sel.switches == 1:
            switched_at = ms * MS
    first_owed = 500 * MS + 500
    assert switched_at == first_owed - 500 + 9 * MS, switched_at
    switch = sel.last_switch
    assert (switch.to_lane, switch.at_seq, switch.reason) == (1, 1101, ls.RING_FULL), switch
    assert switch.ahead == ls.PENDING
    assert 8 * MS <= switch.silent_ns < 9 * MS, switch
    assert sel.switch_counts[ls.RING_FULL] == 1
    assert seqs(out) == list(range(1, 2101))
    assert sel.overwritten == 0


def a_ring_overwritten_by_a_consumer_that_does_not_ask_is_counted():
    sel = ls.LaneSelector(cfg())
    for seq in range(1, ls.PENDING + 4):
        assert sel.has_room(1) == (seq <= ls.PENDING)
        sel.push(1, stamped(1, seq, MS + seq))
    assert sel.overwritten == 3
    assert not sel.has_room(7)


def a_selected_lane_late_by_less_than_the_dead_time_is_kept():
    sel, out, lanes = ls.LaneSelector(cfg()), [], [deque(), deque()]
    # Lane 1 publishes every millisecond. Lane 0 keeps pace but every 100 ms is descheduled and
    # publishes the first sample it owes 7.9 ms late (just under the dead time), with the others
    # it owes at once.
    for seq in range(1, 3001):
        lanes[1].append(stamped(1, seq, seq * MS))
        phase = seq % 100
        ns = (seq - phase) * MS + 8_900_000 + phase if 1 <= phase <= 9 else seq * MS + 100_000
        lanes[0].append(stamped(0, seq, ns))
    for step in range(1, 31_001):
        consume(sel, lanes, step * MS // 10, out)
    assert sel.switches == 0
    assert len(out) == 3000 and all(lane == 0 for _, lane in out)


def a_selected_lane_late_by_more_than_the_dead_time_is_left_and_the_silence_reported():
    sel, out, lanes = ls.LaneSelector(cfg()), [], [deque(), deque()]
    # As above, but lane 0's pause at 1000 ms lasts 12 ms.
    for seq in range(1, 1101):
        lanes[1].append(stamped(1, seq, seq * MS))
        ns = 1012 * MS + 100_000 + seq if 1001 <= seq <= 1012 else seq * MS + 100_000
        lanes[0].append(stamped(0, seq, ns))
    for step in range(1, 11_101):
        consume(sel, lanes, step * MS // 10, out)
    # Lane 0's last sample came at 1000.1 ms, the first it owed (1001) at 1001 ms: silent from
    # then; lane 1's 1009 at 1009 ms makes 8 ms and 9 samples ahead.
    switch = sel.last_switch
    assert switch == ls.Switch(0, 1, ls.SILENT, 1001, ahead=9, silent_ns=8 * MS), switch
    text = "lane 0 → 1 at seq 1001: lane 0 silent 8.0 ms while lane 1 was 9 samples ahead"
    assert str(switch) == text, str(switch)
    assert sel.switch_counts[ls.SILENT] == 1
    assert seqs(out) == list(range(1, 1101))


def a_burst_after_a_gap_in_the_input_is_not_a_dead_lane():
    sel, out, lanes = ls.LaneSelector(cfg()), [], [deque(), deque()]
    for seq in range(1, 101):
        for lane, queue in enumerate(lanes):
            queue.append(stamped(lane, seq, seq * MS))
    # The input stops for 300 ms and 300 samples arrive at once at 400 ms: lane 1 takes them at
    # 20 µs each, lane 0 gets a CPU 6 ms later; then both carry on in real time. Lane 0's last
    # sample is 306 ms old when lane 1 is 100 ahead, but it was never more than 6 ms late with
    # work to do.
    for seq in range(101, 401):
        lanes[1].append(stamped(1, seq, 400 * MS + (seq - 100) * 20_000))
        lanes[0].append(stamped(0, seq, 406 * MS + (seq - 100) * 20_000))
    for seq in range(401, 601):
        lanes[1].append(stamped(1, seq, seq * 2 * MS))
        lanes[0].append(stamped(0, seq, seq * 2 * MS + 300_000))
    for step in range(1, 12_101):
        consume(sel, lanes, step * MS // 10, out)
    assert sel.switches == 0
    assert len(out) == 600 and all(lane == 0 for _, lane in out)


def a_restarted_lane_is_not_chosen_until_it_settled_and_then_only_when_needed():
    sel, out = ls.LaneSelector(cfg()), []
    # Lane 0 dies at 200; lane 1 carries on. Lane 0 restarts at 300 by taking over, is trusted
    # from 400, but lane 1 stays selected: no flip-flop.
    for seq in range(1, 1001):
        sel.push(1, nav(1, seq, 1))
        if seq <= 200:
            sel.push(0, nav(0, seq, 1))
        elif seq >= 300:
            sel.push(0, nav(0, seq, 300))
        drain(sel, out)
    assert sel.switches == 1
    assert len(out) == 1000 and all(lane == 1 for _, lane in out[200:])


def a_selected_lane_that_resets_is_left_for_a_trusted_one_after_the_dwell():
    sel, out = ls.LaneSelector(cfg()), []
    # Lane 0 restarts its alignment at 500 (aligning from then on); lane 1 is trusted.
    for seq in range(1, 701):
        sel.push(0, nav(0, seq, 1) if seq < 500 else aligning(0, seq))
        sel.push(1, nav(1, seq, 1))
        drain(sel, out)
    assert sel.last_switch == ls.Switch(0, 1, ls.UNTRUSTED, 500, distrust=ls.DISTRUST_ALIGNING)
    assert seqs(out) == list(range(1, 701))


def an_untrusted_lane_is_taken_only_when_the_selected_one_is_dead():
    sel, out = ls.LaneSelector(cfg()), []
    # Both aligning at first: no quality switch between two untrusted lanes.
    for seq in range(1, 51):
        sel.push(1, aligning(1, seq))
        sel.push(0, aligning(0, seq))
        drain(sel, out)
    assert sel.switches == 0
    # Lane 0 dies while lane 1 still aligns: lane 1 is taken (no output would be worse).
    for seq in range(51, 81):
        sel.push(1, aligning(1, seq))
        drain(sel, out)
    assert sel.selected == 1
    assert len(out) == 80


def a_sample_the_selected_lane_skipped_is_filled_from_the_other():
    sel, out = ls.LaneSelector(cfg()), []
    for seq in range(1, 31):
        if seq != 11:
            sel.push(0, nav(0, seq, 1))
        sel.push(1, nav(1, seq, 1))
        drain(sel, out)
    assert len(out) == 30
    assert out[10] == (11, 1)
    assert all(lane == 0 for seq, lane in out if seq != 11)
    assert (sel.filled, sel.switches) == (1, 0)


def gaps_in_both_lanes_pass_through_without_a_switch():
    sel, out = ls.LaneSelector(cfg()), []
    # Both lanes miss 101..=150 (the input never existed); the standby publishes first after it.
    for seq in list(range(1, 101)) + list(range(151, 301)):
        sel.push(1, nav(1, seq, 1))
        drain(sel, out)
        sel.push(0, nav(0, seq, 1))
        drain(sel, out)
    assert sel.switches == 0
    assert len(out) == 250


def quality_switches_respect_the_dwell_time():
    sel, out = ls.LaneSelector(cfg()), []
    # Lane 0 dies at 200 (dead switch at 201) and comes back trusted; lane 1 resets at 220,
    # within the 50-sample dwell: the quality switch back waits until 251.
    for seq in range(1, 401):
        if seq <= 200 or seq >= 209:
            sel.push(0, nav(0, seq, 1))
        sel.push(1, nav(1, seq, 1) if seq < 220 else aligning(1, seq))
        drain(sel, out)
    assert sel.switches == 2
    assert sel.last_switch == ls.Switch(1, 0, ls.UNTRUSTED, 251, distrust=ls.DISTRUST_ALIGNING)
    assert len(out) == 400


def a_lane_that_restarts_below_its_pending_samples_drops_them():
    sel, out = ls.LaneSelector(cfg()), []
    for seq in range(1, 11):
        sel.push(0, nav(0, seq, 1))
        drain(sel, out)
    # Lane 1 got ahead (21..=30), then restarted from 12: its pending 21..=30 are stale.
    for seq in range(21, 31):
        sel.push(1, nav(1, seq, 1))
    sel.push(1, nav(1, 12, 12))
    assert [s.header.origin_seq for s in sel._pending[1]] == [12]


def defaults_are_the_rust_ones(rust: dict):
    python = dataclasses.asdict(ls.SelectorConfig())
    python["pending"] = ls.PENDING
    python["lanes"] = ls.LANES
    python["navigator_stage"] = ls.NAVIGATOR_STAGE
    python["usable_modes"] = list(ls.USABLE_MODES)
    assert python == rust, f"Python {python} != Rust {rust}"


CASES = [
    only_a_settled_usable_mode_is_trusted,
    healthy_lanes_deliver_the_selected_lane_once_in_order,
    a_killed_lane_loses_no_sample_and_the_gap_is_the_switch_lag,
    a_late_sample_is_not_a_failure,
    a_burst_with_the_other_lane_ahead_is_not_a_dead_lane,
    a_silent_lane_is_left_after_the_dead_time,
    a_starved_lane_is_not_left_for_one_that_just_reset,
    a_burst_that_fills_the_ring_waits_for_the_dead_time_and_loses_nothing,
    a_ring_overwritten_by_a_consumer_that_does_not_ask_is_counted,
    a_selected_lane_late_by_less_than_the_dead_time_is_kept,
    a_selected_lane_late_by_more_than_the_dead_time_is_left_and_the_silence_reported,
    a_burst_after_a_gap_in_the_input_is_not_a_dead_lane,
    a_restarted_lane_is_not_chosen_until_it_settled_and_then_only_when_needed,
    a_selected_lane_that_resets_is_left_for_a_trusted_one_after_the_dwell,
    an_untrusted_lane_is_taken_only_when_the_selected_one_is_dead,
    a_sample_the_selected_lane_skipped_is_filled_from_the_other,
    gaps_in_both_lanes_pass_through_without_a_switch,
    quality_switches_respect_the_dwell_time,
    a_lane_that_restarts_below_its_pending_samples_drops_them,
]


def main() -> int:
    for case in CASES:
        case()
    count = len(CASES)
    if len(sys.argv) > 1:
        defaults_are_the_rust_ones(json.loads(sys.argv[1]))
        count += 1
    print(f"{count} cases pass")
    return 0


if __name__ == "__main__":
    sys.exit(main())
