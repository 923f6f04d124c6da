#!/usr/bin/env python3
"""Checks of bench/rtps_breakdown.py on a pcap this test writes: every byte attributed, to
the right kind and topic. Run: python3 bench/rtps_breakdown_test.py (stdlib only)."""
import contextlib
import io
import os
import struct
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rtps_breakdown as rb  # noqa: E402

AIR = bytes.fromhex("0f" * 12)     # the aircraft participant's GUID prefix
GROUND = bytes.fromhex("a0" * 12)  # the ground's
WRITER = 0x00000D02                # a user writer of the aircraft
OTHER = 0x00000602


def sub(sid, body, flags=0x01):
    return struct.pack("<BBH", sid, flags, len(body)) + body


def rtps(prefix, *subs):
    return b"RTPS\x02\x03\x01\x0f" + prefix + b"".join(subs)


def eid(e):
    return struct.pack(">I", e)


def data(writer, payload, reader=0):
    # extraFlags, octetsToInlineQos (16), readerId, writerId, writerSN (high, low), payload
    return sub(0x15, b"\0\0" + struct.pack("<H", 16) + eid(reader) + eid(writer) + struct.pack("<iI", 0, 1) + payload,
               flags=0x05)


def heartbeat(writer):
    return sub(0x07, eid(0) + eid(writer) + struct.pack("<iIiIi", 0, 1, 0, 1, 1))


def acknack(writer):
    return sub(0x06, eid(0) + eid(writer) + struct.pack("<iII", 0, 2, 0) + struct.pack("<i", 1))


def info_dst(prefix):
    return sub(0x0E, prefix)


def info_ts():
    return sub(0x09, struct.pack("<II", 1, 2))


def sedp(prefix, entity, topic):
    name = topic.encode() + b"\0"
    name_param = struct.pack("<I", len(name)) + name
    name_param += b"\0" * (-len(name_param) % 4)
    params = (struct.pack("<HH", rb.PID_TOPIC_NAME, len(name_param)) + name_param +
              struct.pack("<HH", rb.PID_ENDPOINT_GUID, 16) + prefix + eid(entity) + struct.pack("<HH", rb.PID_SENTINEL, 0))
    return data(0x000003C2, b"\x00\x03\x00\x00" + params)


def ipv4(src, dst, udp_payload, ident=1, frag=None):
    """An Ethernet frame (or, with frag=(offset, more, part), one IP fragment of it)."""
    udp = struct.pack(">HHHH", 7411, 7411, 8 + len(udp_payload), 0) + udp_payload
    body, flags = udp, 0
    if frag:
        off, more, body = frag
        flags = (0x2000 if more else 0) | (off // 8)
    ip = struct.pack(">BBHHHBBH4s4s", 0x45, 0, 20 + len(body), ident, flags, 64, 17, 0, bytes(src), bytes(dst)) + body
    return b"\0" * 12 + b"\x08\x00" + ip


def pcap(frames):
    out = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)
    for t, f in frames:
        out += struct.pack("<IIII", int(t), int(round((t % 1) * 1e6)), len(f), len(f)) + f
    return out


A, G = [10, 79, 0, 1], [10, 79, 0, 2]


class Breakdown(unittest.TestCase):
    def run_tool(self, frames, *args):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "t.pcap")
            with open(path, "wb") as fh:
                fh.write(pcap(frames))
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                rc = rb.main([path, *args])
            self.assertEqual(rc, 0)
            return out.getvalue()

    @staticmethod
    def row(text, name):
        for line in text.splitlines():
            cells = [c.strip() for c in line.strip("|").split("|")]
            if cells and cells[0] == name:
                return cells
        raise AssertionError(f"no row {name!r} in:\n{text}")

    def test_every_byte_goes_to_its_kind_and_topic(self):
        user = rtps(AIR, info_dst(GROUND), info_ts(), data(WRITER, b"\0\1\0\0" + b"x" * 40))
        hb = rtps(AIR, info_dst(GROUND), heartbeat(WRITER))
        ack = rtps(GROUND, info_dst(AIR), acknack(WRITER))
        frames = [(100.0, ipv4(A, G, rtps(AIR, sedp(AIR, WRITER, "pmu/health"), sedp(AIR, OTHER, "pmu/voltages")))),
                  # The ground's own writer of the same entity id: only INFO_DST tells them apart.
                  (100.5, ipv4(G, A, rtps(GROUND, sedp(GROUND, WRITER, "pmu/command")))),
                  (101.0, ipv4(A, G, user)), (101.5, ipv4(A, G, hb)), (101.6, ipv4(G, A, ack)),
                  (102.0, b"\xff" * 12 + b"\x08\x06" + b"\0" * 28)]  # ARP: not RTPS
        # 10 s window from 100 s: byte counts are B/s x 10.
        text = self.run_tool(frames, "--start", "100", "--end", "110", "--local", "10.79.0.2")
        ip = lambda payload: 28 + len(payload)
        sedp_bytes = ip(rtps(AIR, sedp(AIR, WRITER, "pmu/health"), sedp(AIR, OTHER, "pmu/voltages")))
        health = ip(user) + ip(hb) + ip(ack)
        sedp_bytes += ip(rtps(GROUND, sedp(GROUND, WRITER, "pmu/command")))
        total = sedp_bytes + health + 42
        self.assertIn(f"{total} IP bytes in 10.0 s", text)
        self.assertIn("3 endpoints announced", text)
        # By kind: each submessage's 4-byte header counted with it.
        self.assertEqual(self.row(text, "ACKNACK")[1], f"{len(acknack(WRITER)) / 10:.0f}")
        self.assertEqual(self.row(text, "HEARTBEAT")[1], f"{len(heartbeat(WRITER)) / 10:.0f}")
        self.assertEqual(self.row(text, "INFO_DST")[1], f"{3 * 16 / 10:.0f}")
        self.assertEqual(self.row(text, "RTPS header")[1], f"{5 * 20 / 10:.0f}")
        self.assertEqual(self.row(text, "IP/UDP headers")[1], f"{5 * 28 / 10:.0f}")
        self.assertEqual(self.row(text, "not RTPS")[1], f"{42 / 10:.0f}")
        # By topic: the ACKNACK (sent by the ground) is the aircraft writer's, through INFO_DST.
        h = self.row(text, "pmu/health")
        self.assertEqual(h[1], f"{health / 10:.0f}")
        self.assertEqual(h[3], "0.1")  # one sample in 10 s
        self.assertEqual(h[-1], f"{ip(ack) / 10:.0f}")  # sent by the ground
        self.assertEqual(h[-2], f"{(ip(user) + ip(hb)) / 10:.0f}")  # received from the aircraft
        self.assertEqual(self.row(text, "discovery")[1], f"{sedp_bytes / 10:.0f}")
        self.assertEqual(self.row(text, "total")[1], f"{total / 10:.0f}")

    def test_the_window_comes_from_step_marks_and_fragments_are_reassembled(self):
        big = rtps(AIR, info_dst(GROUND), info_ts(), data(WRITER, b"\0\1\0\0" + b"y" * 3000))
        udp = struct.pack(">HHHH", 7411, 7411, 8 + len(big), 0) + big
        parts = [(0, True, udp[:1480]), (1480, True, udp[1480:2960]), (2960, False, udp[2960:])]
        frames = [(50.0, ipv4(A, G, rtps(AIR, sedp(AIR, WRITER, "pmu/low_rate/voltages"))))]
        frames += [(60.0 + i / 100, ipv4(A, G, big, ident=7, frag=p)) for i, p in enumerate(parts)]
        frames += [(70.0, ipv4(A, G, rtps(AIR, info_dst(GROUND), heartbeat(WRITER))))]  # after the window
        with tempfile.TemporaryDirectory() as d:
            steps = os.path.join(d, "steps")
            with open(steps, "w") as fh:
                fh.write("low 1.0 55.0\nlow-end 11.0 65.0\nfinished 20.0 80.0\n")
            text = self.run_tool(frames, "--steps", steps, "--from", "low", "--to", "low-end")
        frag_bytes = sum(20 + len(p[2]) for p in parts)
        self.assertIn(f"{frag_bytes} IP bytes in 10.0 s", text)
        v = self.row(text, "pmu/low_rate/voltages")
        self.assertEqual(v[1], f"{frag_bytes / 10:.0f}")
        self.assertEqual(v[4], f"{len(data(WRITER, b'x' * 3004)) / 10:.0f}")  # DATA column
        # Three IP headers, one UDP header.
        self.assertEqual(self.row(text, "IP/UDP headers")[1], f"{(3 * 20 + 8) / 10:.0f}")

    def test_pairs_count_heartbeats_and_acknacks_and_which_acknacks_are_pre_emptive(self):
        sedp_pub_writer, sedp_pub_reader = 0x000003C2, 0x000003C7
        pre_emptive = sub(0x06, eid(sedp_pub_reader) + eid(sedp_pub_writer) + struct.pack("<iII", 0, 0, 0) + struct.pack("<i", 1))
        nack = sub(0x06, eid(sedp_pub_reader) + eid(sedp_pub_writer) + struct.pack("<iII", 0, 3, 2) + b"\xc0\0\0\0" +
                   struct.pack("<i", 2))
        hb = sub(0x07, eid(0) + eid(sedp_pub_writer) + struct.pack("<iIiIi", 0, 1, 0, 4, 1))
        # The aircraft's reader asks the ground's writer five times; the ground's writer
        # heartbeats every reader once; the ground's reader nacks the aircraft's writer once.
        frames = [(1.0 + i / 10, ipv4(A, G, rtps(AIR, info_dst(GROUND), pre_emptive))) for i in range(5)]
        frames += [(2.0, ipv4(G, A, rtps(GROUND, hb))), (2.5, ipv4(G, A, rtps(GROUND, info_dst(AIR), nack)))]
        text = self.run_tool(frames, "--start", "0", "--end", "10", "--pairs", "5")
        self.assertIn("3 writer-reader pairs exchanged HEARTBEATs or ACKNACKs", text)
        air, ground = AIR[2:8].hex(), GROUND[2:8].hex()
        self.assertEqual(self.row(text, f"{ground} SEDP publications writer")[1:],
                         [f"{air} SEDP publications reader", "0.0", "0.5", "0.5"])
        rows = [line for line in text.splitlines() if line.startswith(f"| {ground} SEDP publications writer | every reader")]
        self.assertEqual(rows, [f"| {ground} SEDP publications writer | every reader | 0.1 | 0.0 | 0.0 |"])
        self.assertEqual(self.row(text, f"{air} SEDP publications writer")[1:], [f"{ground} SEDP publications reader", "0.0", "0.1", "0.0"])
        # Without --pairs, no such table.
        self.assertNotIn("writer-reader pairs", self.run_tool(frames, "--start", "0", "--end", "10"))

    def test_a_writer_never_announced_is_named_by_its_entity(self):
        frames = [(1.0, ipv4(A, G, rtps(AIR, info_dst(GROUND), heartbeat(0x00001102))))]
        text = self.run_tool(frames, "--start", "0", "--end", "2")
        self.row(text, "unannounced writer 00001102")

    def test_a_step_that_is_not_there_is_an_error_naming_the_steps(self):
        with tempfile.TemporaryDirectory() as d:
            path, steps = os.path.join(d, "t.pcap"), os.path.join(d, "steps")
            with open(path, "wb") as fh:
                fh.write(pcap([(1.0, ipv4(A, G, rtps(AIR)))]))
            with open(steps, "w") as fh:
                fh.write("list 1.0 1.0\n")
            err = io.StringIO()
            with contextlib.redirect_stderr(err):
                self.assertEqual(rb.main([path, "--steps", steps, "--from", "low"]), 2)
            self.assertIn("no step 'low' (steps: list)", err.getvalue())


if __name__ == "__main__":
    unittest.main()
