"""rins's ODOMETRY as one autopilot profile sends it, seen by pymavlink on a live pipeline.

Starts `rins up --scenario uav` with `[mavlink] autopilot = AUTOPILOT` (optionally with a GNSS
receiver, `--gnss`) and checks, from what arrives on the link:
- ODOMETRY's frames: `generic` and `px4` LOCAL_NED (1) with child BODY_FRD (12), `ardupilot`
  LOCAL_FRD (20) with BODY_FRD; estimator type UNKNOWN (0); the covariance diagonal finite and
  positive; the pose of every message finite for `ardupilot` (it sends nothing it cannot show);
- quality: ⌊100·σ₀²/(σ₀² + σ_h²)⌋ of the message's own covariance (σ₀ = 10 m), so below 50 whenever
  the horizontal σ exceeds 10 m. Without GNSS the solution is free-inertial and its σ_h must be
  seen past 10 m (the run waits up to WAIT_SIGMA_S for it); with GNSS it must stay within 10 m;
- the global origin: `px4` sends SET_GPS_GLOBAL_ORIGIN, `ardupilot` COMMAND_INT
  MAV_CMD_DO_SET_GLOBAL_ORIGIN (611, frame GLOBAL), both to system 1, with the local frame's origin
  (checked against GLOBAL_POSITION_INT and LOCAL_POSITION_NED of the same time: the origin plus
  the local position is the global position, within 5 cm for nine pairs in ten), again every
  10 s ± 1 s; `generic` sends neither.

Usage: python mavlink_autopilot.py RINS_BINARY PORT CONFIG AUTOPILOT [--gnss]
(RINS_IPC_PREFIX / RINS_IPC_ROOT isolate the run; CONFIG has `[mavlink] autopilot = AUTOPILOT`.)
Prints one JSON line of what it measured; exits non-zero on the first failed check.
"""

import json
import math
import os
import signal
import subprocess
import sys
import time

os.environ["MAVLINK20"] = "1"  # MAVLink 2 framing and the extension fields (ODOMETRY quality)
from pymavlink import mavutil  # noqa: E402

QUALITY_SIGMA_M = 10.0  # [mavlink] odometry_quality_sigma_m as built in
FRAMES = {"generic": (1, 12), "px4": (1, 12), "ardupilot": (20, 12)}
COVARIANCE_DIAGONAL = [0, 6, 11, 15, 18, 20]
MAV_CMD_DO_SET_GLOBAL_ORIGIN = 611
WAIT_SIGMA_S = 60.0  # free-inertial σ_h passes 10 m about 25 s after alignment
WGS84_A = 6378137.0
WGS84_E2 = 6.69437999014e-3


def fail(why, measured):
    measured["failed"] = why
    print(json.dumps(measured))
    sys.exit(1)


def horizontal_sigma_m(m):
    return math.sqrt(m.pose_covariance[0] + m.pose_covariance[6])


def expected_quality(sigma):
    s0 = QUALITY_SIGMA_M ** 2
    return max(1, math.floor(100 * s0 / (s0 + sigma * sigma)))


def origin_of(m):
    """(latitude °, longitude °, altitude m) of an origin announcement, or None."""
    if m.get_type() == "SET_GPS_GLOBAL_ORIGIN":
        return m.latitude * 1e-7, m.longitude * 1e-7, m.altitude * 1e-3
    if m.get_type() == "COMMAND_INT" and m.command == MAV_CMD_DO_SET_GLOBAL_ORIGIN:
        return m.x * 1e-7, m.y * 1e-7, m.z
    return None


def check_odometry(m, autopilot, gnss, measured, seen):
    frames = (m.frame_id, m.child_frame_id)
    if frames != FRAMES[autopilot]:
        fail(f"ODOMETRY frames {frames}, expected {FRAMES[autopilot]}", measured)
    if m.estimator_type != 0:
        fail(f"ODOMETRY estimator_type {m.estimator_type}", measured)
    if m.quality < 0:
        # Nothing to show: the pose is NaN; for PX4 the velocity too; ArduPilot never gets one.
        if autopilot == "ardupilot":
            fail("ODOMETRY of nothing to show sent to ArduPilot", measured)
        if not all(math.isnan(v) for v in (m.x, m.y, m.z)):
            fail(f"ODOMETRY quality -1 with a position {m.x, m.y, m.z}", measured)
        if autopilot == "px4" and not all(math.isnan(v) for v in (m.vx, m.vy, m.vz)):
            fail(f"ODOMETRY quality -1 with a velocity for PX4 {m.vx, m.vy, m.vz}", measured)
        seen["invalid"] += 1
        return
    diag = [m.pose_covariance[i] for i in COVARIANCE_DIAGONAL]
    if not all(math.isfinite(v) and v > 0 for v in diag):
        fail(f"ODOMETRY covariance diagonal {diag}", measured)
    if not all(math.isfinite(v) for v in (m.x, m.y, m.z, m.vx, m.vy, m.vz, *m.q)):
        fail(f"ODOMETRY of a usable solution not finite: {m}", measured)
    sigma = horizontal_sigma_m(m)
    expected = expected_quality(sigma)
    # ±1 for the covariance's f32 rounding at a step; a degraded integrity halves it.
    if abs(m.quality - expected) > 1 and abs(m.quality - max(1, expected // 2)) > 1:
        fail(f"ODOMETRY quality {m.quality} for σ_h {sigma:.2f} m (expected {expected})", measured)
    if sigma > QUALITY_SIGMA_M * 1.001 and m.quality >= 50:
        fail(f"ODOMETRY quality {m.quality} for σ_h {sigma:.2f} m > {QUALITY_SIGMA_M} m", measured)
    if gnss and sigma > QUALITY_SIGMA_M:
        fail(f"σ_h {sigma:.2f} m with GNSS", measured)
    seen["sigma"] = [min(seen["sigma"][0], sigma), max(seen["sigma"][1], sigma)]
    seen["quality"] = [min(seen["quality"][0], m.quality), max(seen["quality"][1], m.quality)]
    if sigma > QUALITY_SIGMA_M * 1.001:
        seen["above_sigma0"] += 1


def check_origin_against_positions(origin, globals_by_t, locals_by_t, measured):
    """The origin plus a local position is the global position of the same sample. Both lanes
    deliver samples of the same time, and with GNSS they may differ by a decimetre when an update
    reached one of them first: a pair may then come from two lanes, so nine in ten pairs must
    agree within 5 cm (a wrong origin is metres to kilometres off in every pair)."""
    lat0, lon0, alt0 = origin
    # WGS84 radii of curvature at the origin: within a few kilometres of it the tangent-plane
    # approximation is good to millimetres, and GLOBAL_POSITION_INT's 1e-7° is about 1 cm.
    s2 = math.sin(math.radians(lat0)) ** 2
    meridian = WGS84_A * (1 - WGS84_E2) / (1 - WGS84_E2 * s2) ** 1.5
    prime_vertical = WGS84_A / math.sqrt(1 - WGS84_E2 * s2)
    errors = []
    for t, g in globals_by_t.items():
        loc = locals_by_t.get(t)
        if loc is None:
            continue
        north = math.radians(g.lat * 1e-7 - lat0) * (meridian + alt0)
        east = math.radians(g.lon * 1e-7 - lon0) * (prime_vertical + alt0) * \
            math.cos(math.radians(lat0))
        down = -(g.alt * 1e-3 - alt0)
        errors.append(math.dist((north, east, down), (loc.x, loc.y, loc.z)))
    if len(errors) < 10:
        fail(f"{len(errors)} GLOBAL_POSITION_INT matched a LOCAL_POSITION_NED", measured)
    errors.sort()
    within = sum(1 for e in errors if e <= 0.05) / len(errors)
    measured["origin_plus_local_m"] = {"median": round(errors[len(errors) // 2], 4),
                                       "worst": round(errors[-1], 4),
                                       "within_5cm": round(within, 3), "pairs": len(errors)}
    if within < 0.9:
        fail(f"origin {origin} + local position off the global position: "
             f"{measured['origin_plus_local_m']}", measured)


def main():
    rins, port, config, autopilot = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
    gnss = "--gnss" in sys.argv[5:]
    measured = {"autopilot": autopilot, "gnss": gnss}
    conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255)
    args = [rins, "up", "--scenario", "uav", "--duration", "150", "--json", "--config", config,
            "--mavlink", f"udpout:127.0.0.1:{port}"]
    if gnss:
        args.append("--gnss")
    up = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        check(conn, autopilot, gnss, measured)
    finally:
        if up.poll() is None:
            up.send_signal(signal.SIGINT)
        try:
            up.wait(timeout=30)
        except subprocess.TimeoutExpired:
            up.kill()
    print(json.dumps(measured))


def check(conn, autopilot, gnss, measured):
    seen = {"invalid": 0, "above_sigma0": 0, "sigma": [math.inf, 0.0], "quality": [101, -2],
            "odometry": 0}
    origins = []  # (receive time, origin, target system)
    globals_by_t, locals_by_t = {}, {}
    start = time.monotonic()
    usable_at = None
    # Until σ_h is past σ₀ without GNSS (or 20 s of a usable solution with it), and at least 25 s
    # of a usable solution so that the origin is seen again.
    while True:
        now = time.monotonic()
        if now - start > 120:
            measured["seen"] = seen
            fail("no usable solution long enough, or σ_h never passed 10 m", measured)
        if usable_at is not None and now - usable_at >= 25 and \
                (gnss or seen["above_sigma0"] >= 30 or now - usable_at > WAIT_SIGMA_S):
            break
        m = conn.recv_match(blocking=True, timeout=0.5)
        if m is None or m.get_type() == "BAD_DATA":
            continue
        kind = m.get_type()
        if kind == "ODOMETRY":
            seen["odometry"] += 1
            check_odometry(m, autopilot, gnss, measured, seen)
            if m.quality > 0 and usable_at is None:
                usable_at = now
        elif kind == "GLOBAL_POSITION_INT":
            globals_by_t[m.time_boot_ms] = m
        elif kind == "LOCAL_POSITION_NED":
            locals_by_t[m.time_boot_ms] = m
        else:
            origin = origin_of(m)
            if origin is not None:
                target = m.target_system
                if autopilot == "ardupilot" and (m.frame != 0 or m.target_component != 1):
                    fail(f"origin command frame {m.frame} component {m.target_component}", measured)
                origins.append((now, origin, target, kind))
    measured["seen"] = seen
    if not gnss and seen["above_sigma0"] < 30:
        fail(f"σ_h reached only {seen['sigma'][1]:.2f} m: quality above σ₀ not exercised", measured)
    if seen["quality"][1] < 50:
        fail(f"quality never reached 50: {seen['quality']}", measured)
    if autopilot == "generic":
        if origins:
            fail(f"generic profile announced an origin: {origins}", measured)
        return
    want = "SET_GPS_GLOBAL_ORIGIN" if autopilot == "px4" else "COMMAND_INT"
    if len(origins) < 2:
        fail(f"{len(origins)} origin announcements", measured)
    kinds = {k for _, _, _, k in origins}
    targets = {t for _, _, t, _ in origins}
    values = {o for _, o, _, _ in origins}
    if kinds != {want} or targets != {1} or len(values) != 1:
        fail(f"origin announcements {origins}", measured)
    gaps = [b[0] - a[0] for a, b in zip(origins, origins[1:])]
    if not all(9.0 <= g <= 11.0 for g in gaps):
        fail(f"origin announced at gaps {gaps} s", measured)
    origin = origins[0][1]
    check_origin_against_positions(origin, globals_by_t, locals_by_t, measured)
    measured["origin"] = [round(origin[0], 7), round(origin[1], 7), round(origin[2], 3)]
    measured["origin_kind"] = want
    measured["origin_gaps_s"] = [round(g, 2) for g in gaps]


if __name__ == "__main__":
    main()
