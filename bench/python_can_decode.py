#!/usr/bin/env python3
"""Reference offline decoder for bench/offline_decode.sh (benchmark issue item 7).

What a user would write without pmu-dds: python-can's candump -L log reader plus `struct`
decoding of the Millswood 250W PMU packets (protocol v1.9), printing one JSON line per
frame with the field names of `pmuctl decode --json` (docs/interface.md 3.2).

  python_can_decode.py LOG                        decode LOG to stdout
  python_can_decode.py --check PMUCTL_OUT LOG [--lines N]
      decode the first N (default 5000) frames of LOG and compare them with the first N
      lines of `pmuctl decode --json LOG` output: same packets, same values (numbers to
      5e-7). Exit 1 on any disagreement, so the benchmark never times a wrong reference.

Only PMU frames are decoded: CANopen battery/MPPT frames (11-bit ids), which pmuctl also
decodes, are reported as "not a PMU frame". Needs python3-can (Debian: /usr/bin/python3).
"""
import argparse
import itertools
import json
import math
import struct
import sys

try:
    import can
except ImportError:
    sys.exit(f"python_can_decode.py: python-can is missing for {sys.executable} (Debian: apt install python3-can)")

GROUP = 0x1E
NO_SENSOR = -128
NAMES = {
    0x00: "voltages", 0x01: "currents", 0x02: "battery_energy", 0x03: "temperatures", 0x04: "status",
    0x0F: "measurement_request", 0x10: "avionics_voltage", 0x11: "payload_voltage", 0x12: "servo_voltage",
    0x13: "battery_voltage", 0x14: "packet_period", 0x15: "packets_streamed", 0x16: "temperature_offset",
    0x17: "upper_temperature_limit", 0x18: "power_up_state", 0x19: "cranking_time", 0x1B: "can_address",
    0x20: "outputs", 0x21: "enable_outputs", 0x22: "disable_outputs", 0x23: "generation",
    0x24: "engine_start", 0x25: "engine_stop", 0x26: "reset", 0x30: "serial", 0x31: "firmware",
}
# Data length of each packet (table 1); 0x24..0x26 carry none.
LENGTHS = {0x00: 7, 0x01: 6, 0x02: 4, 0x03: 5, 0x04: 5, 0x1B: 2, 0x24: 0, 0x25: 0, 0x26: 0, 0x30: 2, 0x31: 6}
# Packets that a zero-length frame asks for (a "get"): up to 0x20, generation, serial, firmware.
GETS = {p for p in NAMES if p <= 0x20} | {0x23, 0x30, 0x31}
# Parameters 0x10..0x1B (tables 8..18): struct format and divisor (None: an integer).
PARAMS = {0x10: ("B", 10), 0x11: ("B", 10), 0x12: ("B", 10), 0x13: ("B", 10), 0x14: ("B", 10),
          0x15: ("B", None), 0x16: ("B", None), 0x17: ("B", None), 0x18: ("B", None),
          0x19: ("B", 10), 0x1B: (">H", None)}
CURRENT_FW = (1, 17)  # firmware assumed until a device's 0x31 reply is seen


def temperature(raw):
    return None if raw == NO_SENSOR else float(raw)  # every temperature (interface.md 1.1)


def decode_values(packet, data, fw):
    """The "values" object of one data frame; fw is the device's (major, minor)."""
    if packet == 0x00:
        a, o, p, s, ba, bb, g = struct.unpack("7B", data)
        return {"avionics": a / 10, "output_28v": o / 5, "payload": p / 10, "servo": s / 10,
                "battery_a": ba / 10, "battery_b": bb / 10, "generator": g / 2.5}
    if packet == 0x01:
        a, o, p, s, ba, bb = struct.unpack("BbBBbb", data)
        return {"avionics": a / 10, "output_28v": o / 10, "payload": p / 10, "servo": s / 10,
                "battery_a": ba / 10, "battery_b": bb / 10}
    if packet == 0x02:
        a, b = struct.unpack(">hh", data)
        return {"battery_a_mah": a, "battery_b_mah": b}
    if packet == 0x03:
        i, ba, bb, g, s = struct.unpack("5b", data)
        external = fw >= (1, 12)  # external sensors from firmware 1.12
        return {"internal": temperature(i),
                "battery_a": temperature(ba) if external else None,
                "battery_b": temperature(bb) if external else None,
                "generator": temperature(g) if external else None,
                "starter": temperature(s)}
    if packet == 0x04:
        rpm, f0, f1, f2 = struct.unpack(">HBBB", data)
        soa = fw >= (1, 16)  # flag register 0 bit 6: start button before 1.16
        return {"generator_rpm": rpm, "generation_enabled": bool(f0 & 0x10),
                "thermal_shutdown": bool(f0 & 0x20),
                "soa_shutdown": soa and bool(f0 & 0x40), "start_button": not soa and bool(f0 & 0x40),
                "payload_shed": bool(f0 & 0x80), "starter_ready": fw >= (1, 12) and bool(f1 & 0x80),
                "avionics_servo_on": bool(f2 & 1), "payload_on": bool(f2 & 2),
                "charger_a_on": bool(f2 & 4), "charger_b_on": bool(f2 & 8)}
    if packet == 0x0F:
        return {"measurements": data[0] & 0x1F}
    if packet in PARAMS:
        fmt, divisor = PARAMS[packet]
        (raw,) = struct.unpack(fmt, data)
        return {NAMES[packet]: raw / divisor if divisor else raw}
    if packet in (0x20, 0x21, 0x22):
        return {"outputs": data[0] & 0x0F}
    if packet == 0x23:
        return {"generation_enabled": bool(data[0] & 1)}
    if packet == 0x30:
        (serial,) = struct.unpack(">H", data)
        return {"serial_number": serial}
    if packet == 0x31:
        major, minor, day, month, year = struct.unpack(">BBBBH", data)
        return {"firmware_major": major, "firmware_minor": minor, "build_year": year,
                "build_month": month, "build_day": day}
    return {}


def decode_message(msg, line, learned):
    """One python-can Message -> one JSON-ready dict (or {"line", "error"})."""
    can_id, data, length = msg.arbitration_id, bytes(msg.data or b""), msg.dlc
    if not msg.is_extended_id or can_id >> 24 != GROUP:
        return {"line": line, "error": f"id {can_id:X} is not a PMU frame (needs a 29-bit id in group 0x1E)"}
    packet, address = (can_id >> 16) & 0xFF, can_id & 0xFFFF
    name = NAMES.get(packet)
    if name is None:
        return {"line": line, "error": f"unknown packet 0x{packet:02X} in id {can_id:08X}"}
    if msg.is_remote_frame:
        return {"line": line, "error": f"remote frame for packet 0x{packet:02X} {name} (the PMU uses data frames only)"}
    if length > 8:
        return {"line": line, "error": f"length {length} exceeds 8 bytes"}
    want = LENGTHS.get(packet, 1)
    request = length == 0 and (want == 0 or packet in GETS)
    if not request and (want == 0 or length != want):
        get = ", or 0 for a get" if packet in GETS else ""
        return {"line": line, "error": f"wrong length {length} for packet 0x{packet:02X} {name} (expects {want}{get})"}

    fw = learned.get(address)
    out = {"time": msg.timestamp, "interface": str(msg.channel), "id": f"{can_id:08X}",
           "address": address, "packet": name}
    if request:
        out["request"] = True
    else:
        out["values"] = decode_values(packet, data, fw or CURRENT_FW)
        if packet == 0x04:
            out["bit6_meaning"] = "soa_shutdown" if (fw or CURRENT_FW) >= (1, 16) else "start_button"
            out["firmware"] = f"{fw[0]}.{fw[1]}" if fw else None
        if packet == 0x31:
            learned[address] = (data[0], data[1])
    if packet == 0x0F and fw and fw < (1, 14):
        out["note"] = f"measurement_request needs firmware 1.14 (device has {fw[0]}.{fw[1]})"
    return out


def decode_log(path):
    learned = {}  # address -> firmware (major, minor) from 0x31 replies in the log
    # The reader skips blank lines, so "line" is the frame number (the line number in a log without any).
    for line, msg in enumerate(can.CanutilsLogReader(path), start=1):
        yield decode_message(msg, line, learned)


def same(a, b):
    """JSON values equal, numbers to 5e-7 (a time may differ in its last bit); a bool is not a number."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    numbers = all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in (a, b))
    if not numbers:
        return type(a) is type(b) and a == b
    return math.isclose(a, b, rel_tol=0, abs_tol=5e-7)


def check(expected_path, log_path, lines):
    telemetry = {"voltages", "currents", "battery_energy", "temperatures", "status"}
    ours = list(itertools.islice(decode_log(log_path), lines))
    with open(expected_path) as f:
        theirs = [json.loads(text) for text in itertools.islice(f, lines)]
    bad = [] if len(ours) == len(theirs) else [f"{len(ours)} frames from python-can, {len(theirs)} lines from pmuctl"]
    values = 0
    for n, (a, b) in enumerate(zip(ours, theirs), start=1):
        if not same(a, b):
            bad.append(f"line {n}:\n  python-can: {json.dumps(a)}\n  pmuctl:     {json.dumps(b)}")
        elif a.get("packet") in telemetry:
            values += len(a.get("values", {}))
    if values == 0:
        bad.append(f"no telemetry values compared in {len(ours)} lines")
    if bad:
        print(f"python_can_decode.py --check: DECODERS DISAGREE ({len(bad)} problems in {len(ours)} lines):", file=sys.stderr)
        print("\n".join(bad[:5]), file=sys.stderr)
        return 1
    print(f"python_can_decode.py --check: {len(ours)} lines agree ({values} telemetry values)", file=sys.stderr)
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", help="candump -L log")
    ap.add_argument("--check", metavar="PMUCTL_OUT", help="compare with `pmuctl decode --json` output instead")
    ap.add_argument("--lines", type=int, default=5000, help="lines compared by --check")
    args = ap.parse_args()
    if args.check:
        return check(args.check, args.log, args.lines)
    for obj in decode_log(args.log):
        print(json.dumps(obj))
    return 0


if __name__ == "__main__":
    sys.exit(main())
