"""End-to-end check of rins's MAVLink 2 output, as a ground station or companion computer sees it.

Starts `rins up --mavlink udpout:127.0.0.1:PORT` (the simulator's uav flight), listens with
pymavlink and checks: the message set and each stream's rate (±10 %), the attitude against
`rins echo nav` for the same samples, the odometry covariance against the solution's, TIMESYNC
answers, a STATUSTEXT after `rins inject gyro1 dead`, the reset counter and a lane-switch text after
the lane the stream delivers is killed, and re-admission commands acknowledged with fusion's answer;
ODOMETRY's quality against its own covariance (below 50 whenever the horizontal σ exceeds
QUALITY_SIGMA_M) and SYS_STATUS's bits (only what rins has: no GPS without a receiver, no extended
sensor) and its load (the pipeline's CPU, never 0 while it runs).
The link is signed with KEY_HEX: pymavlink takes only messages carrying a valid signature, signs
what it sends, and an unsigned command must go unanswered.

Usage: python mavlink_stream.py RINS_BINARY PORT CONFIG KEY_HEX   (RINS_IPC_PREFIX / RINS_IPC_ROOT
isolate the run; CONFIG is a configuration file that accepts MAVLink commands signed with the key
KEY_HEX, 64 hexadecimal digits, from system 255)
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

RATES = {  # the configuration's defaults
    "HEARTBEAT": 1.0,
    "ATTITUDE_QUATERNION": 50.0,
    "GLOBAL_POSITION_INT": 25.0,
    "LOCAL_POSITION_NED": 30.0,
    "ODOMETRY": 30.0,
    "HIGHRES_IMU": 50.0,
    "SYS_STATUS": 2.0,
    "VIBRATION": 0.5,
}
COVARIANCE_DIAGONAL = [0, 6, 11, 15, 18, 20]
QUALITY_SIGMA_M = 10.0  # [mavlink] odometry_quality_sigma_m, the configuration's default
# SYS_STATUS bits (MAV_SYS_STATUS_SENSOR): what rins always has, and GPS, which needs [gnss].
SENSOR_3D_GYRO, SENSOR_3D_ACCEL, SENSOR_GPS, AHRS = 1, 2, 32, 1 << 21
LANE_SWITCH = "rins lane "  # "rins lane 0->1: <why>": the lane left, the lane delivering now
LANE_SERVICES = ["navigator", "navigator-standby"]


def fail(why, measured):
    measured["failed"] = why
    print(json.dumps(measured))
    sys.exit(1)


def rotation_between_deg(a, b):
    """The angle of the rotation from attitude a to attitude b (quaternions w, x, y, z), degrees;
    well conditioned near zero, unlike an arccosine of their dot product."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    # conj(a) * b
    w = aw * bw + ax * bx + ay * by + az * bz
    x = aw * bx - ax * bw - ay * bz + az * by
    y = aw * by + ax * bz - ay * bw - az * bx
    z = aw * bz - ax * by + ay * bx - az * bw
    return math.degrees(2 * math.atan2(math.sqrt(x * x + y * y + z * z), abs(w)))


def msg_time_s(m):
    """The measurement time a message carries, s; None for those without one."""
    if hasattr(m, "time_usec"):
        return m.time_usec / 1e6
    if hasattr(m, "time_boot_ms"):
        return m.time_boot_ms / 1e3
    return None


class Listener:
    def __init__(self, port, key):
        self.conn = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255)
        # Unsigned or badly signed messages are dropped by pymavlink: everything checked below
        # arrived signed with the key.
        self.conn.setup_signing(key, sign_outgoing=True)
        # Every STATUSTEXT seen, and the lane the stream delivers: a loaded machine can starve a
        # lane past the selector's dead time at any moment, and the stream then goes on from the
        # other lane (announced once, whichever check was waiting at the time).
        self.texts = []
        self.lane = 0

    def recv(self, timeout):
        m = self.conn.recv_match(blocking=True, timeout=timeout)
        if m is not None and m.get_type() == "STATUSTEXT":
            self.texts.append(m.text)
            if m.text.startswith(LANE_SWITCH):
                self.lane = int(m.text[len(LANE_SWITCH):].split(":")[0].split("->")[1])
        return m

    def collect(self, seconds, keep=None):
        """Every message for `seconds` of wall time."""
        out = []
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            m = self.recv(0.2)
            if m is None or m.get_type() == "BAD_DATA":
                continue
            out.append((time.monotonic(), m))
            if keep is not None and keep(m):
                break
        return out

    def wait_for(self, seconds, pred):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            m = self.recv(0.2)
            if m is not None and m.get_type() != "BAD_DATA" and pred(m):
                return m
        return None


def readmit(listener, sensor, channel, measured):
    """Sends a re-admission (MAV_CMD_USER_1) and returns the results acknowledged: in progress
    first, then the outcome."""
    listener.conn.mav.command_long_send(1, 197, mavutil.mavlink.MAV_CMD_USER_1, 0,
                                        sensor, channel, 0, 0, 0, 0, 0)
    results = []
    end = time.monotonic() + 15
    while time.monotonic() < end:
        ack = listener.wait_for(1, lambda m: m.get_type() == "COMMAND_ACK")
        if ack is None:
            continue
        results.append(ack.result)
        if ack.result != mavutil.mavlink.MAV_RESULT_IN_PROGRESS:
            break
    if not results or results[0] != mavutil.mavlink.MAV_RESULT_IN_PROGRESS:
        fail(f"re-admission not acknowledged in progress first: {results}", measured)
    return results


def horizontal_sigma_m(m):
    """The horizontal position σ of an ODOMETRY message: the root of its north and east
    variances' sum."""
    return math.sqrt(m.pose_covariance[0] + m.pose_covariance[6])


def check_quality(odometry, measured):
    """Each usable ODOMETRY's quality is ⌊100·σ₀²/(σ₀² + σ_h²)⌋ of its own covariance (at least 1;
    ±1 for the covariance's f32 rounding at a step), so below 50 whenever σ_h exceeds σ₀."""
    s0 = QUALITY_SIGMA_M ** 2
    sigmas, qualities = [], []
    for m in odometry:
        if m.quality < 0:
            continue
        sigma = horizontal_sigma_m(m)
        expected = max(1, math.floor(100 * s0 / (s0 + sigma * sigma)))
        # A degraded integrity halves it.
        if abs(m.quality - expected) > 1 and abs(m.quality - max(1, expected // 2)) > 1:
            fail(f"ODOMETRY quality {m.quality} for σ_h {sigma:.2f} m (expected {expected})", measured)
        if sigma > QUALITY_SIGMA_M * 1.001 and m.quality >= 50:  # beyond the f32 rounding
            fail(f"ODOMETRY quality {m.quality} for σ_h {sigma:.2f} m > {QUALITY_SIGMA_M} m", measured)
        sigmas.append(sigma)
        qualities.append(m.quality)
    if not qualities:
        fail("no usable ODOMETRY in the window", measured)
    # Without GNSS the horizontal σ grows past σ₀ within seconds of alignment (about 16 m after the
    # 12 s window): the case the quality exists for must have been seen.
    if max(sigmas) <= QUALITY_SIGMA_M:
        fail(f"σ_h stayed within {max(sigmas):.2f} m: quality above σ₀ not exercised", measured)
    measured["odometry_sigma_h_m"] = [round(min(sigmas), 3), round(max(sigmas), 3)]
    measured["odometry_quality"] = [min(qualities), max(qualities)]


def check_sys_status(messages, measured):
    """SYS_STATUS names only what rins has: gyro, accelerometer and AHRS always, no GPS (this run
    has no GNSS receiver), nothing of the extended set, health only of what is present."""
    for m in messages:
        present = m.onboard_control_sensors_present
        always = SENSOR_3D_GYRO | SENSOR_3D_ACCEL | AHRS
        if present & always != always or present & SENSOR_GPS:
            fail(f"SYS_STATUS present {present:#x}", measured)
        if m.onboard_control_sensors_enabled != present or \
                m.onboard_control_sensors_health & ~present:
            fail(f"SYS_STATUS present {present:#x} enabled {m.onboard_control_sensors_enabled:#x} "
                 f"health {m.onboard_control_sensors_health:#x}", measured)
        extended = [m.onboard_control_sensors_present_extended,
                    m.onboard_control_sensors_enabled_extended,
                    m.onboard_control_sensors_health_extended]
        if any(extended) or m.load > 1000:
            fail(f"SYS_STATUS extended {extended} load {m.load}", measured)
    # The load is the pipeline's CPU (in permille of the processors it may use): a running
    # pipeline never uses none. The first message may come before the first interval is measured.
    if not all(m.load > 0 for m in messages[2:]):
        fail(f"SYS_STATUS load {[m.load for m in messages]}: a running pipeline uses CPU", measured)
    last = messages[-1]
    measured["sys_status"] = [last.onboard_control_sensors_present,
                              last.onboard_control_sensors_health]


def run(rins, *args, timeout=30):
    return subprocess.run([rins, *args], capture_output=True, text=True, timeout=timeout)


def main():
    rins, port, config = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    key = bytes.fromhex(sys.argv[4])
    measured = {}
    listener = Listener(port, key)
    up = subprocess.Popen(
        [rins, "up", "--scenario", "uav", "--duration", "120", "--json", "--config", config,
         "--mavlink", f"udpout:127.0.0.1:{port}"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )
    try:
        check(rins, listener, measured)
    finally:
        if up.poll() is None:
            up.send_signal(signal.SIGINT)
        try:
            up.wait(timeout=30)
        except subprocess.TimeoutExpired:
            up.kill()
    print(json.dumps(measured))


def check(rins, listener, measured):
    # 1. A heartbeat of an onboard controller, then a usable solution.
    hb = listener.wait_for(30, lambda m: m.get_type() == "HEARTBEAT")
    if hb is None:
        fail("no HEARTBEAT within 30 s", measured)
    if hb.type != mavutil.mavlink.MAV_TYPE_ONBOARD_CONTROLLER or \
            hb.autopilot != mavutil.mavlink.MAV_AUTOPILOT_INVALID or hb.get_srcComponent() != 197:
        fail(f"heartbeat type {hb.type} autopilot {hb.autopilot} comp {hb.get_srcComponent()}", measured)
    nav = listener.wait_for(90, lambda m: m.get_type() == "ODOMETRY" and m.quality > 0)
    if nav is None:
        fail("no ODOMETRY of a usable solution (quality > 0) within 90 s", measured)

    # 2. The message set and the rates, over 12 s, from the measurement times.
    window = listener.collect(12.0)
    by_type = {}
    for t, m in window:
        by_type.setdefault(m.get_type(), []).append((t, m))
    rates = {}
    for name, hz in RATES.items():
        got = by_type.get(name, [])
        if len(got) < 3:
            fail(f"{name}: {len(got)} messages in 12 s", measured)
        times = [msg_time_s(m) for _, m in got]
        if times[0] is None:  # no timestamp: the receive times
            times = [t for t, _ in got]
        rate = (len(times) - 1) / (times[-1] - times[0])
        rates[name] = round(rate, 3)
        if abs(rate - hz) > 0.1 * hz:
            fail(f"{name}: {rate:.3f} Hz, configured {hz}", measured)
    measured["rates_hz"] = rates
    check_quality([m for _, m in by_type["ODOMETRY"]], measured)
    check_sys_status([m for _, m in by_type["SYS_STATUS"]], measured)

    # 3. The attitude and covariance of ODOMETRY against `rins echo nav` for the same samples.
    echo = subprocess.Popen([rins, "echo", "nav", "--raw", "--count", "1000"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    odo = [m for _, m in listener.collect(1.5) if m.get_type() == "ODOMETRY"]
    out, _ = echo.communicate(timeout=30)
    samples = {}
    for line in out.splitlines():
        s = json.loads(line)
        samples[s["header"]["origin_rx_ns"] // 1000] = s
    # Both streams follow a lane selector of their own, and may take a sample from different lanes.
    # The lanes compute the same solution unless an aiding reading reached one of them late (a
    # starved altimeter: then they differ by hundredths of a degree). Same sample, same attitude:
    # normally equal to the f32 rounding, every one within 0.1° (a frame or order mistake in the
    # message would be tens of degrees off: the vehicle flies at 30° heading).
    matched = exact = 0
    for m in odo:
        s = samples.get(m.time_usec)
        if s is None:
            continue
        matched += 1
        angle_deg = rotation_between_deg(m.q, s["quaternion"])
        worst = max(abs(a - b) for a, b in zip(m.q, s["quaternion"]))
        if angle_deg > 0.1:
            fail(f"ODOMETRY q {list(m.q)} is {angle_deg:.4f}° from nav {s['quaternion']}", measured)
        if worst <= 1e-7:
            exact += 1
        p = s["covariance_diag"]
        expected = [p[6], p[7], p[8], p[0], p[1], p[2]]
        # The same lane's sample (the attitude equal to the f32 rounding): the covariance to 1 %. The
        # other lane's, after an aiding reading reached one of them late: to 10 %.
        tolerance = 1e-2 if worst <= 1e-7 else 1e-1
        for i, e in zip(COVARIANCE_DIAGONAL, expected):
            if not math.isclose(m.pose_covariance[i], e, rel_tol=tolerance, abs_tol=1e-30):
                fail(f"pose covariance [{i}] {m.pose_covariance[i]} != {e}", measured)
    if matched < 10:
        fail(f"{matched} ODOMETRY samples matched `rins echo nav`, {exact} exactly", measured)
    measured["odometry_exact_of_matched"] = [exact, matched]

    # 4. TIMESYNC is answered with our ts1 and rins's clock.
    listener.conn.mav.timesync_send(0, 123456789)
    ts = listener.wait_for(5, lambda m: m.get_type() == "TIMESYNC" and m.ts1 == 123456789)
    if ts is None or ts.tc1 <= 0:
        fail("TIMESYNC not answered", measured)
    measured["timesync_tc1_ns"] = ts.tc1

    # 5. Commands: an unsigned one is refused (no answer at all), one rins does not carry out, and a
    # re-admission of a channel in service.
    listener.conn.mav.signing.sign_outgoing = False
    listener.conn.mav.command_long_send(1, 197, mavutil.mavlink.MAV_CMD_USER_1, 0,
                                        1.0, 0.0, 0, 0, 0, 0, 0)
    listener.conn.mav.signing.sign_outgoing = True
    ack = listener.wait_for(3, lambda m: m.get_type() == "COMMAND_ACK")
    measured["unsigned_command_answered"] = ack is not None
    if ack is not None:
        fail(f"an unsigned command was answered: {ack}", measured)
    listener.conn.mav.command_long_send(1, 197, mavutil.mavlink.MAV_CMD_COMPONENT_ARM_DISARM,
                                        0, 1, 0, 0, 0, 0, 0, 0)
    ack = listener.wait_for(5, lambda m: m.get_type() == "COMMAND_ACK")
    if ack is None or ack.result != mavutil.mavlink.MAV_RESULT_UNSUPPORTED:
        fail(f"ARM_DISARM: expected UNSUPPORTED, got {ack}", measured)
    measured["readmit_in_service"] = readmit(listener, 1.0, 0.0, measured)
    if measured["readmit_in_service"][-1] != mavutil.mavlink.MAV_RESULT_ACCEPTED:
        fail(f"re-admitting accel0 in service: {measured['readmit_in_service']}", measured)

    # 6. A dead gyro is announced.
    r = run(rins, "inject", "gyro1", "dead")
    if r.returncode != 0:
        fail(f"rins inject: {r.stderr}", measured)
    text = listener.wait_for(10, lambda m: m.get_type() == "STATUSTEXT" and "gyro1 excluded" in m.text)
    if text is None:
        fail("no STATUSTEXT 'gyro1 excluded' within 10 s of the injection", measured)
    measured["statustext_fault"] = text.text
    # Asked back while still dead: excluded again during its probation, acknowledged as failed.
    measured["readmit_dead"] = readmit(listener, 0.0, 1.0, measured)
    if measured["readmit_dead"][-1] != mavutil.mavlink.MAV_RESULT_FAILED:
        fail(f"re-admitting the dead gyro1: {measured['readmit_dead']}", measured)

    # 7. The lane the stream delivers killed: it switches, the reset counter moves, the covariance
    # stays.
    before = listener.wait_for(5, lambda m: m.get_type() == "ODOMETRY")
    status = json.loads(run(rins, "status", "--json").stdout.strip().splitlines()[-1])
    killed = LANE_SERVICES[listener.lane]
    pid = next(s["pid"] for s in status["services"] if s["service"] == killed)
    os.kill(pid, signal.SIGKILL)
    switch = listener.wait_for(10, lambda m: m.get_type() == "STATUSTEXT" and LANE_SWITCH in m.text)
    if switch is None:
        measured["statustexts"] = listener.texts
        fail(f"no lane-switch STATUSTEXT within 10 s of killing {killed}", measured)
    after = listener.wait_for(5, lambda m: m.get_type() == "ODOMETRY")
    if after is None or after.reset_counter == before.reset_counter:
        fail(f"reset counter {before.reset_counter} unchanged after the lane switch", measured)
    diag = [after.pose_covariance[i] for i in COVARIANCE_DIAGONAL]
    if not all(math.isfinite(v) and v > 0 for v in diag) or after.quality < 0:
        fail(f"after the switch: covariance {diag}, quality {after.quality}", measured)
    measured["reset_counter"] = [before.reset_counter, after.reset_counter]
    measured["statustext_switch"] = switch.text
    measured["lane_killed"] = killed


if __name__ == "__main__":
    main()
