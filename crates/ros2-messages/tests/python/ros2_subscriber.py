"""A ROS 2 reader of rins on another host, without ROS: a Zenoh session (eclipse-zenoh) that
subscribes to the key expressions rmw_zenoh uses for rins's topics, checks each sample's rmw_zenoh
attachment, decodes the CDR with ROS 2's own message definitions, and writes what it received as
JSON: per topic the count, the receive times and the latency from rins publishing the sample (the
attachment's source timestamp) to here; the odometry and IMU values (floats as their bits); the
liveliness tokens it saw; the diagnostics' status names.

    python ros2_subscriber.py --mode router --listen tcp/10.0.0.2:7447 --seconds 10 --out r.json
    [--domain 0 --namespace /rins]

It runs until --seconds after the first odometry sample (or --timeout without one), or SIGTERM."""

import argparse
import json
import signal
import struct
import sys
import threading
import time

import zenoh

from ros2_definitions import bits, decoder, quat, vec

TYPES = {
    "odom": ("nav_msgs/Odometry", "nav_msgs::msg::dds_::Odometry_",
             "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"),
    "imu": ("sensor_msgs/Imu", "sensor_msgs::msg::dds_::Imu_",
            "RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b"),
    "fix": ("sensor_msgs/NavSatFix", "sensor_msgs::msg::dds_::NavSatFix_",
            "RIHS01_62223ab3fe210a15976021da7afddc9e200dc9ec75231c1b6a557fc598a65404"),
    "/diagnostics": ("diagnostic_msgs/DiagnosticArray",
                     "diagnostic_msgs::msg::dds_::DiagnosticArray_",
                     "RIHS01_5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e"),
}


def key(domain, namespace, topic, dds, rihs):
    full = topic if topic.startswith("/") else namespace.rstrip("/") + "/" + topic
    return f"{domain}/{full.strip('/')}/{dds}/{rihs}"


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--mode", default="router")
    p.add_argument("--listen", action="append", default=[])
    p.add_argument("--connect", action="append", default=[])
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--timeout", type=float, default=60.0)
    p.add_argument("--domain", type=int, default=0)
    p.add_argument("--namespace", default="/rins")
    p.add_argument("--keep", type=int, default=2000, help="odometry/imu samples kept with values")
    p.add_argument("--out", required=True)
    a = p.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", json.dumps(a.mode))
    if a.listen:
        conf.insert_json5("listen/endpoints", json.dumps(a.listen))
    if a.connect:
        conf.insert_json5("connect/endpoints", json.dumps(a.connect))
    conf.insert_json5("scouting/multicast/enabled", "false")
    session = zenoh.open(conf)

    lock = threading.Lock()
    state = {t: {"count": 0, "received_ns": [], "latency_ns": [], "bad_attachment": 0,
                 "undecodable": 0, "sequence_gaps": 0, "last_seq": None, "samples": []}
             for t in TYPES}
    first_odom = threading.Event()

    def handler(topic, decode):
        def on_sample(sample):
            now = time.clock_gettime_ns(time.CLOCK_REALTIME)
            s = state[topic]
            att = sample.attachment
            att = bytes(att.to_bytes()) if att is not None else b""
            with lock:
                if len(att) != 33 or att[16] != 16:
                    s["bad_attachment"] += 1
                    return
                seq, source_ns = struct.unpack("<qq", att[:16])
                if s["last_seq"] is not None and seq != s["last_seq"] + 1:
                    s["sequence_gaps"] += 1
                s["last_seq"] = seq
                try:
                    msg = decode(bytes(sample.payload.to_bytes()))
                except Exception:  # noqa: BLE001 - garbage from the network is counted
                    s["undecodable"] += 1
                    return
                s["count"] += 1
                s["received_ns"].append(now)
                s["latency_ns"].append(now - source_ns)
                kept = len(s["samples"]) < a.keep
                if topic == "odom":
                    first_odom.set()
                    if kept:
                        s["samples"].append({
                            "stamp": [msg.header.stamp.sec, msg.header.stamp.nanosec],
                            "frame_id": msg.header.frame_id,
                            "child_frame_id": msg.child_frame_id,
                            "position": vec(msg.pose.pose.position),
                            "orientation": quat(msg.pose.pose.orientation),
                            "linear": vec(msg.twist.twist.linear),
                            "angular": vec(msg.twist.twist.angular),
                        })
                elif topic == "imu" and kept:
                    s["samples"].append({
                        "stamp": [msg.header.stamp.sec, msg.header.stamp.nanosec],
                        "frame_id": msg.header.frame_id,
                        "angular_velocity": vec(msg.angular_velocity),
                        "linear_acceleration": vec(msg.linear_acceleration),
                    })
                elif topic == "fix" and kept:
                    s["samples"].append({"status": msg.status.status,
                                         "lla": bits([msg.latitude, msg.longitude, msg.altitude])})
                elif topic == "/diagnostics" and kept:
                    s["samples"].append({"names": [x.name for x in msg.status],
                                         "levels": [x.level for x in msg.status]})
        return on_sample

    subscribers = []
    keys = {}
    for topic, (name, dds, rihs) in TYPES.items():
        k = key(a.domain, a.namespace, topic, dds, rihs)
        keys[topic] = k
        subscribers.append(session.declare_subscriber(k, handler(topic, decoder(name))))

    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    deadline = time.monotonic() + a.timeout
    while not stop.is_set() and not first_odom.is_set() and time.monotonic() < deadline:
        time.sleep(0.02)
    tokens = []
    if first_odom.is_set():
        end = time.monotonic() + a.seconds
        while not stop.is_set() and time.monotonic() < end:
            time.sleep(0.02)
        try:
            for reply in session.liveliness().get(f"@ros2_lv/{a.domain}/**", timeout=2.0):
                if reply.ok is not None:
                    tokens.append(str(reply.ok.key_expr))
        except Exception as e:  # noqa: BLE001
            tokens.append(f"error: {e}")
    with lock:
        out = {"keys": keys, "tokens": sorted(tokens), "topics": {}}
        for topic, s in state.items():
            s = dict(s)
            s.pop("last_seq")
            out["topics"][topic] = s
    for sub in subscribers:
        sub.undeclare()
    session.close()
    with open(a.out, "w") as f:
        json.dump(out, f)
    print(json.dumps({t: out["topics"][t]["count"] for t in TYPES}))
    return 0 if first_odom.is_set() else 1


if __name__ == "__main__":
    sys.exit(main())
