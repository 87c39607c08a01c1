"""Choosing between the two navigator lanes: one contiguous navigation stream out of two.

The same rule as the Rust `LaneSelector` (services/navigator/src/lanes/selector.rs), which rins's
own consumers use. Both lanes run the same filter on the same fused IMU samples and stamp each
solution with the sequence number of its IMU sample (`header.origin_seq`), so their outputs are
interchangeable sample by sample. The selector delivers every sequence number once, in order, from
the lane it has selected, and keeps the other lane's samples that are ahead of the output so that
a switch continues exactly at the next sequence number: killing the selected lane loses no sample.

Switching rule:
- Dead lane: the selected lane has delivered nothing beyond the output while the other lane is
  `switch_lag` samples ahead and the selected lane has been silent for `dead_after_ns`
  (`dead_after_untrusted_ns` when the other lane is not trusted). Silence is measured on the
  navigators' publish times (`header.stage_pub_ns[NAVIGATOR_STAGE]`), from the later of the
  selected lane's last sample and the other lane's first sample the selected lane still owes: a
  lane is late only once there was work for it to do. So one late sample is no failure, nor is a
  burst after a gap in the input in which one lane is briefly ahead. Samples without publish
  times are judged by the count alone.
- Full ring: the other lane's pending samples fill the ring (`PENDING`). The consumer then stops
  taking that lane's samples (`has_room`; they wait in its subscriber's queue), and the selected
  lane is still only left once it has been silent for the dead time, on the consumer's clock
  (`pop(now_ns)`, CLOCK_MONOTONIC as the navigators stamp: `time.monotonic_ns()`).
- Untrusted lane: the selected lane is aligning, invalid or younger than `settle` samples, while
  the other lane is trusted and has the next sample, and `min_dwell` samples have passed since the
  last switch. A lane that just reset is only taken when the selected one is dead.
- Holes in the selected lane (a sample it skipped that the other lane has) are filled from the
  other lane without switching.
- Nothing else switches: a healthy selected lane stays selected (no preferred lane to return to).

Every switch says why (`Switch.reason`: `SILENT`, `BEHIND`, `RING_FULL` or `UNTRUSTED`) and is
counted by cause (`LaneSelector.switch_counts`).

Pure logic: samples are anything with the fields of `rins_topics.NavState` (`mode`,
`solution_start_seq`, `quaternion`, `header.origin_seq`, `header.stage_pub_ns`); neither iceoryx2
nor a running deployment is needed.
"""

import math
from collections import deque
from dataclasses import dataclass

#: Number of navigator lanes.
LANES = 2
#: Pending samples kept per lane: more than any switch lag and than a burst that builds up while
#: the selected lane is silent for less than the dead time, so a switch always finds the next one.
PENDING = 512
#: Index of the navigator's publish time in `header.stage_pub_ns`.
NAVIGATOR_STAGE = 3
#: `NavMode` values: aligning, and those of a usable solution (navigating, coasting).
ALIGNING_MODE = 0
USABLE_MODES = (1, 2)

#: Why the selector left a lane (`Switch.reason`).
SILENT = "silent"
BEHIND = "behind"
RING_FULL = "ring-full"
UNTRUSTED = "untrusted"
#: Why a solution is not trusted (`distrust`).
DISTRUST_ALIGNING = "aligning"
DISTRUST_INVALID = "invalid"
DISTRUST_YOUNG = "too young"
DISTRUST_NON_FINITE = "non-finite"


@dataclass(frozen=True)
class SelectorConfig:
    """When the selector leaves a lane for the other; the defaults are rins's (1 kHz: a dead lane
    is left after 8 ms, 100 ms for a lane not trusted yet; a solution is trusted after 2 s; at
    most one quality switch per second)."""

    #: Samples the other lane must be ahead of the output before the selected lane counts as dead.
    switch_lag: int = 8
    #: And how long the selected lane must have been silent while the other lane published, ns.
    dead_after_ns: int = 8_000_000
    #: The same when the other lane is not trusted.
    dead_after_untrusted_ns: int = 100_000_000
    #: Samples a solution must have run (since alignment or takeover) before it is trusted.
    settle: int = 2000
    #: Samples between a switch and a quality switch.
    min_dwell: int = 1000


@dataclass(frozen=True)
class Switch:
    """A change of the lane delivering, and what the selector saw when it switched."""

    from_lane: int
    to_lane: int
    #: `SILENT`, `BEHIND`, `RING_FULL` or `UNTRUSTED`.
    reason: str
    #: Sequence number of the first sample delivered from the new lane.
    at_seq: int
    #: Samples of the other lane pending ahead of the output (dead-lane switches).
    ahead: "int | None" = None
    #: How long the selected lane had been silent, ns (`SILENT`, `RING_FULL`).
    silent_ns: "int | None" = None
    #: Why the selected lane's solution was not trusted (`UNTRUSTED`), a `DISTRUST_` name.
    distrust: "str | None" = None

    def __str__(self) -> str:
        """`lane 0 → 1 at seq 1234: lane 0 silent 12.3 ms while lane 1 was 15 samples ahead`."""
        a, b = self.from_lane, self.to_lane
        head = f"lane {a} → {b} at seq {self.at_seq}: "
        ms = (self.silent_ns or 0) * 1e-6
        if self.reason == SILENT:
            ahead = f"{self.ahead} samples ahead"
            return head + f"lane {a} silent {ms:.1f} ms while lane {b} was {ahead}"
        if self.reason == BEHIND:
            ahead = f"{self.ahead} samples ahead (no publish times)"
            return head + f"lane {a} silent while lane {b} was {ahead}"
        if self.reason == RING_FULL:
            filled = f"lane {b}'s {self.ahead} pending samples filled the ring"
            return head + f"{filled}, lane {a} silent {ms:.1f} ms"
        return head + f"lane {a} {self.distrust}, lane {b} trusted"


def seq_of(sample) -> int:
    return sample.header.origin_seq


def published_ns(sample) -> "int | None":
    """The navigator's publish time of `sample`; None when it carries none."""
    return sample.header.stage_pub_ns[NAVIGATOR_STAGE] or None


def distrust(sample, settle: int) -> "str | None":
    """Why `sample` is not a solution the selector may choose for quality; None when it is."""
    if sample.mode == ALIGNING_MODE:
        return DISTRUST_ALIGNING
    if sample.mode not in USABLE_MODES:
        return DISTRUST_INVALID
    start = sample.solution_start_seq
    if start == 0 or max(seq_of(sample) - start, 0) < settle:
        return DISTRUST_YOUNG
    if not all(math.isfinite(q) for q in sample.quaternion):
        return DISTRUST_NON_FINITE
    return None


def trusted(sample, settle: int) -> bool:
    """A solution the selector may choose for quality: usable mode, settled, finite attitude."""
    return distrust(sample, settle) is None


class LaneSelector:
    """See the module documentation. Feed each lane's samples with `push` while `has_room`, take
    the output with `pop` until it returns None."""

    def __init__(self, config: SelectorConfig = SelectorConfig()):
        self.config = config
        self._pending = [deque() for _ in range(LANES)]
        #: The lane delivering now.
        self.selected = 0
        self._last_delivered = None
        # Navigator publish time of the newest sample delivered from the selected lane (0: none
        # yet, or unstamped).
        self._selected_published_ns = 0
        self._last_switch_seq = None
        #: Lane changes since start, by cause (`SILENT`, `BEHIND`, `RING_FULL`, `UNTRUSTED`).
        self.switch_counts = {SILENT: 0, BEHIND: 0, RING_FULL: 0, UNTRUSTED: 0}
        #: The most recent lane change (a `Switch`), or None.
        self.last_switch = None
        #: Samples taken from the other lane to fill a hole in the selected lane's output.
        self.filled = 0
        #: Pending samples overwritten because a lane's ring was full (pushed without `has_room`).
        self.overwritten = 0

    @property
    def switches(self) -> int:
        """Lane changes since start."""
        return sum(self.switch_counts.values())

    def has_room(self, lane: int) -> bool:
        """Whether `lane`'s ring takes another sample without overwriting its oldest pending one;
        a consumer leaves a lane's samples in its queue while not."""
        return lane in range(LANES) and len(self._pending[lane]) < PENDING

    def next_seq(self, lane: int) -> "int | None":
        """Sequence number of `lane`'s oldest pending sample."""
        if lane not in range(LANES) or not self._pending[lane]:
            return None
        return seq_of(self._pending[lane][0])

    def push(self, lane: int, sample) -> None:
        """Takes one sample of `lane` (a lane's samples arrive in sequence order). Samples at or
        before the output are useless and dropped; when the ring is full the oldest pending one
        goes (counted in `overwritten`)."""
        if lane not in range(LANES):
            return
        seq = seq_of(sample)
        if self._last_delivered is not None and seq <= self._last_delivered:
            return
        queue = self._pending[lane]
        # A lane that restarted begins again below what it had pending: its old samples are stale.
        while queue and seq_of(queue[-1]) >= seq:
            queue.pop()
        if len(queue) == PENDING:
            queue.popleft()
            self.overwritten += 1
        queue.append(sample)

    def pop(self, now_ns: int = 0):
        """The next sample of the output stream, or None until one is due. `now_ns` is the
        consumer's clock (`time.monotonic_ns()`), which times a full ring of the other lane; 0
        reads time from the navigators' publish times alone."""
        self._discard_delivered()
        other = 1 - self.selected
        switch = self._switch(other, now_ns)
        if switch is not None:
            self._switch_to(switch)
        selected = self._pending[self.selected]
        if not selected:
            return None
        # A sample the selected lane skipped but the other lane has fills the hole; the selection
        # stays (one missing sample is a glitch, not a failure).
        candidates = self._pending[other]
        if candidates and seq_of(candidates[0]) < seq_of(selected[0]):
            self.filled += 1
            sample = candidates.popleft()
        else:
            sample = selected.popleft()
            self._selected_published_ns = published_ns(sample) or 0
        self._last_delivered = seq_of(sample)
        return sample

    def _discard_delivered(self) -> None:
        if self._last_delivered is None:
            return
        for queue in self._pending:
            while queue and seq_of(queue[0]) <= self._last_delivered:
                queue.popleft()

    def _switch(self, other: int, now_ns: int) -> "Switch | None":
        """The switch to `other` due now, if one is."""
        candidates = self._pending[other]
        if not candidates:
            return None
        candidate = candidates[0]
        settle = self.config.settle
        candidate_distrust = distrust(candidate, settle)
        selected = self._pending[self.selected]
        if not selected:
            return self._dead(other, candidate_distrust is None, now_ns)
        # Untrusted: only towards a trusted lane that has the next sample (not behind the selected
        # one), and not within the dwell time of the last switch.
        nxt = selected[0]
        dwelt = (
            self._last_switch_seq is None
            or max(seq_of(nxt) - self._last_switch_seq, 0) >= self.config.min_dwell
        )
        if not dwelt or candidate_distrust is not None or seq_of(candidate) > seq_of(nxt):
            return None
        why = distrust(nxt, settle)
        if why is None:
            return None
        return self._switch_record(other, UNTRUSTED, distrust=why)

    def _dead(self, other: int, candidate_trusted: bool, now_ns: int) -> "Switch | None":
        """Nothing from the selected lane while the other has samples ahead of the output: dead
        once the other lane is `switch_lag` samples ahead (counted in samples, so that a hole both
        lanes share is no reason) and the selected one silent for the dead time; longer towards a
        lane that is not trusted, so that a selected lane starved of CPU for a few milliseconds
        does not hand the output to one that just reset."""
        pending = self._pending[other]
        ahead = len(pending)
        if ahead < self.config.switch_lag:
            return None
        dead_after = (
            self.config.dead_after_ns
            if candidate_trusted
            else self.config.dead_after_untrusted_ns
        )
        first_owed, newest = published_ns(pending[0]), published_ns(pending[-1])
        if first_owed is None or newest is None:
            return self._switch_record(other, BEHIND, ahead=ahead)
        # Silent since its last sample, or since the other lane published the first sample the
        # selected lane still owes, whichever is later: before that it had nothing to do.
        since = max(self._selected_published_ns, first_owed)
        # With a full ring nothing newer is taken from the other lane: the consumer's clock tells
        # how the silence goes on.
        full = ahead >= PENDING
        clock = max(newest, now_ns) if full else newest
        silent_ns = max(clock - since, 0)
        if silent_ns < dead_after:
            return None
        reason = RING_FULL if full else SILENT
        return self._switch_record(other, reason, ahead=ahead, silent_ns=silent_ns)

    def _switch_record(self, lane: int, reason: str, **seen) -> Switch:
        return Switch(self.selected, lane, reason, seq_of(self._pending[lane][0]), **seen)

    def _switch_to(self, switch: Switch) -> None:
        self.last_switch = switch
        self.selected = switch.to_lane
        # The new lane's clock starts with its first delivery.
        self._selected_published_ns = 0
        self._last_switch_seq = switch.at_seq
        self.switch_counts[switch.reason] += 1
