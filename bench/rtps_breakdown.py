#!/usr/bin/env python3
"""What each byte of a captured DDS link is for: by RTPS submessage kind and by topic.

    bench/rtps_breakdown.py PCAP [--steps FILE --from STEP [--to STEP]] [--start T --end T]
                                 [--local PREFIX] [--pairs N]

Reads a pcap (tcpdump -w; Ethernet, Linux cooked or raw IP; whole packets: a packet cut by
the snaplen is counted by its IP length but its cut submessages as "truncated"), walks
IPv4/UDP/RTPS and attributes every IP byte of the window to
  (a) a kind: the IP and UDP headers, the RTPS header, and each submessage by its id
      (DATA, DATA_FRAG, HEARTBEAT, ACKNACK, GAP, INFO_TS, INFO_DST, ...), its 4-byte
      header included; packets that are not RTPS over UDP are "not RTPS";
  (b) a topic: DATA, DATA_FRAG, HEARTBEAT, GAP and HEARTBEAT_FRAG by their writer,
      ACKNACK and NACK_FRAG by the writer they answer (its GUID prefix is the INFO_DST
      before them, else the packet's destination participant is unknown and the entity id
      alone is looked up); writers' topics are learnt from the SEDP announcements in the
      capture (DATA of 0x000003c2 / 0x000004c2 with PID_TOPIC_NAME and PID_ENDPOINT_GUID),
      wherever they are in it. Builtin entities (SPDP, SEDP, the participant message
      writer, type lookup) are "discovery". A packet's headers and INFO_* submessages are
      shared among the topics of its other submessages in proportion to their bytes.
The window: --start/--end (seconds since the epoch, the capture's clock), or the step marks
of bench/fleet_link.sh --capture (a file of "NAME UPTIME EPOCH" lines): from the step FROM
to the step TO (default: the one after FROM, else the capture's end). IP fragments are
reassembled; a datagram belongs to the window its last fragment arrived in.
Prints markdown: bytes/s by kind, by topic (with the kinds and the two directions), and
the totals. --local ADDRESS (a prefix of this side's IP address, such as 10.79.0.2) makes
the direction columns "sent" and "received"; without it they are by source address.
--pairs N adds the N writer-reader pairs that exchanged the most HEARTBEATs and ACKNACKs,
each with the pre-emptive ACKNACKs among them (an empty set based at 0: the "I am here" a
reader sends a writer it matched until the writer's first heartbeat reaches it). A
participant is its GUID prefix's bytes 2..7 (Fast DDS: host and process), an entity its
builtin name or id; a HEARTBEAT without INFO_DST goes to "every reader".
Python 3 standard library only.
"""
import argparse
import collections
import struct
import sys

SUBMESSAGES = {
    0x01: "PAD", 0x06: "ACKNACK", 0x07: "HEARTBEAT", 0x08: "GAP", 0x09: "INFO_TS",
    0x0C: "INFO_SRC", 0x0D: "INFO_REPLY_IP4", 0x0E: "INFO_DST", 0x0F: "INFO_REPLY",
    0x12: "NACK_FRAG", 0x13: "HEARTBEAT_FRAG", 0x15: "DATA", 0x16: "DATA_FRAG",
}
# Submessages that concern a writer: where its entity id is (offset in the body) and whether
# the writer is the sender (else the receiver: the INFO_DST prefix).
WRITER_OFFSET = {0x15: (8, True), 0x16: (8, True), 0x07: (4, True), 0x08: (4, True), 0x13: (4, True),
                 0x06: (4, False), 0x12: (4, False)}
HEADER_KINDS = ("IP/UDP headers", "RTPS header")
OVERHEAD = "headers, INFO_*"
SEDP_WRITERS = (0x000003C2, 0x000004C2)
PID_SENTINEL, PID_TOPIC_NAME, PID_ENDPOINT_GUID = 0x0001, 0x0005, 0x005A
BUILTIN_NAMES = {
    0x000100C2: "SPDP", 0x000100C7: "SPDP", 0x000003C2: "SEDP", 0x000003C7: "SEDP",
    0x000004C2: "SEDP", 0x000004C7: "SEDP", 0x000200C2: "participant message",
    0x000200C7: "participant message", 0x000300C3: "type lookup", 0x000300C4: "type lookup",
    0x000301C3: "type lookup", 0x000301C4: "type lookup",
}
DISCOVERY = "discovery"


def is_builtin(entity):
    return (entity & 0xC0) == 0xC0


class Packet:
    __slots__ = ("time", "src", "dst", "ip_len", "ip_headers", "udp", "payload")

    def __init__(self, time, src, dst, ip_len, ip_headers, udp, payload):
        self.time, self.src, self.dst = time, src, dst
        self.ip_len = ip_len          # every IP byte of the datagram (all its fragments)
        self.ip_headers = ip_headers  # IP headers (all fragments) + the UDP header
        self.udp = udp                # False: not UDP, or fragments that never completed
        self.payload = payload        # the UDP payload as captured (may be cut by the snaplen)


def read_pcap(path):
    """Yields (time, link type, frame bytes) of each record."""
    with open(path, "rb") as fh:
        head = fh.read(24)
        if len(head) < 24:
            raise ValueError(f"{path}: not a pcap file (shorter than its header)")
        magic = head[:4]
        table = {b"\xd4\xc3\xb2\xa1": ("<", 1e-6), b"\xa1\xb2\xc3\xd4": (">", 1e-6),
                 b"\x4d\x3c\xb2\xa1": ("<", 1e-9), b"\xa1\xb2\x3c\x4d": (">", 1e-9)}
        if magic not in table:
            raise ValueError(f"{path}: not a pcap file (magic {magic.hex()}; pcapng is not read: tcpdump -w writes pcap)")
        endian, unit = table[magic]
        linktype = struct.unpack(endian + "I", head[20:24])[0] & 0x0FFFFFFF
        offset = 24
        while True:
            rec = fh.read(16)
            if not rec:
                return
            if len(rec) < 16:
                raise ValueError(f"{path}: record header cut short at byte {offset}")
            sec, frac, incl, _orig = struct.unpack(endian + "IIII", rec)
            data = fh.read(incl)
            if len(data) < incl:
                raise ValueError(f"{path}: packet cut short at byte {offset}")
            offset += 16 + incl
            yield sec + frac * unit, linktype, data


def ip_of(linktype, frame):
    """The IP packet of a frame, or None when it is not IP (ARP and the like)."""
    if linktype == 1:  # Ethernet
        eth_type, off = struct.unpack(">H", frame[12:14])[0], 14
        while eth_type in (0x8100, 0x88A8) and len(frame) >= off + 4:
            eth_type, off = struct.unpack(">H", frame[off + 2:off + 4])[0], off + 4
    elif linktype == 113:  # Linux cooked (SLL)
        eth_type, off = struct.unpack(">H", frame[14:16])[0], 16
    elif linktype == 276:  # Linux cooked v2
        eth_type, off = struct.unpack(">H", frame[0:2])[0], 20
    elif linktype in (101, 12, 228):  # raw IP
        return frame
    else:
        raise ValueError(f"link type {linktype} is not read (Ethernet, Linux cooked or raw IP)")
    return frame[off:] if eth_type in (0x0800, 0x86DD) else None


def datagrams(records):
    """Yields a Packet per IP datagram (fragments reassembled) and per non-IP frame."""
    pending = {}
    for time, linktype, frame in records:
        ip = ip_of(linktype, frame)
        if ip is None:
            yield Packet(time, "-", "-", len(frame), 0, False, b"")
            continue
        version = ip[0] >> 4
        if version == 6:
            plen = struct.unpack(">H", ip[4:6])[0]
            src, dst = ip[8:24].hex(), ip[24:40].hex()
            if ip[6] == 17 and len(ip) >= 48:
                yield Packet(time, src, dst, 40 + plen, 48, True, ip[48:40 + plen])
            else:
                yield Packet(time, src, dst, 40 + plen, 0, False, b"")
            continue
        ihl = (ip[0] & 0x0F) * 4
        total = struct.unpack(">H", ip[2:4])[0]
        ident = struct.unpack(">H", ip[4:6])[0]
        flags_frag = struct.unpack(">H", ip[6:8])[0]
        more, frag_off = bool(flags_frag & 0x2000), (flags_frag & 0x1FFF) * 8
        proto = ip[9]
        src, dst = ".".join(map(str, ip[12:16])), ".".join(map(str, ip[16:20]))
        body = ip[ihl:total]
        if proto != 17:
            yield Packet(time, src, dst, total, 0, False, b"")
            continue
        if not more and frag_off == 0:
            yield Packet(time, src, dst, total, ihl + 8, True, body[8:])
            continue
        key = (src, dst, ident)
        entry = pending.setdefault(key, {"parts": {}, "bytes": 0, "headers": 0, "end": None})
        entry["parts"][frag_off] = body
        entry["bytes"] += total
        entry["headers"] += ihl
        if not more:
            entry["end"] = frag_off + (total - ihl)
        if entry["end"] is not None:
            data, at = b"", 0
            while at in entry["parts"]:
                data += entry["parts"][at]
                at += len(entry["parts"][at])
            if at >= entry["end"]:
                del pending[key]
                yield Packet(time, src, dst, entry["bytes"], entry["headers"] + 8, True, data[8:])
    for (src, dst, _), entry in pending.items():  # never completed: counted, not read
        yield Packet(None, src, dst, entry["bytes"], 0, False, b"")


def submessages(payload):
    """Yields (id, flags, body, total bytes) of an RTPS message's submessages after its header;
    a submessage cut by the snaplen comes as id None with the bytes left."""
    off = 20
    while off + 4 <= len(payload):
        sid, flags = payload[off], payload[off + 1]
        length = struct.unpack("<H" if flags & 1 else ">H", payload[off + 2:off + 4])[0]
        last = length == 0 and sid not in (0x01, 0x09)
        end = len(payload) if last else off + 4 + length
        if end > len(payload):
            yield None, 0, b"", len(payload) - off
            return
        yield sid, flags, payload[off + 4:end], end - off
        off = end
    if off < len(payload):
        yield None, 0, b"", len(payload) - off


def entity(body, at, flags):
    # Entity ids are octet arrays, whatever the submessage's endianness.
    return struct.unpack(">I", body[at:at + 4])[0] if len(body) >= at + 4 else None


def parameter_list(data):
    """The parameters of a PL_CDR serialized payload: {pid: value bytes}."""
    if len(data) < 4 or data[0] != 0 or data[1] not in (2, 3):
        return {}
    endian = "<" if data[1] == 3 else ">"
    out, off = {}, 4
    while off + 4 <= len(data):
        pid, length = struct.unpack(endian + "HH", data[off:off + 4])
        pid &= 0x3FFF  # the must-understand and vendor bits
        if pid == PID_SENTINEL:
            break
        out.setdefault(pid, data[off + 4:off + 4 + length])
        off += 4 + length
    out["endian"] = endian
    return out


def sedp_endpoint(body, flags):
    """(GUID prefix, entity id, topic) announced by a SEDP DATA body, or None."""
    if len(body) < 20:
        return None
    endian = "<" if flags & 1 else ">"
    to_qos = struct.unpack(endian + "H", body[2:4])[0]
    at = 4 + to_qos
    if flags & 0x02:  # inline QoS: a parameter list up to its sentinel
        while at + 4 <= len(body):
            pid, length = struct.unpack(endian + "HH", body[at:at + 4])
            at += 4 + length
            if pid == PID_SENTINEL:
                break
    if not flags & 0x04:  # no data: a dispose or unregister
        return None
    params = parameter_list(body[at:])
    guid, name = params.get(PID_ENDPOINT_GUID), params.get(PID_TOPIC_NAME)
    if not guid or len(guid) < 16 or not name or len(name) < 4:
        return None
    n = struct.unpack(params["endian"] + "I", name[:4])[0]
    topic = name[4:4 + n].split(b"\0")[0].decode("utf-8", "replace")
    return guid[:12].hex(), struct.unpack(">I", guid[12:16])[0], topic


def learn_topics(packets):
    """{(prefix, entity): topic} and {entity: {topics}} from every SEDP announcement."""
    by_guid, by_entity = {}, collections.defaultdict(set)
    for p in packets:
        if not p.udp or p.payload[:4] != b"RTPS":
            continue
        for sid, flags, body, _ in submessages(p.payload):
            if sid == 0x15 and entity(body, 8, flags) in SEDP_WRITERS:
                found = sedp_endpoint(body, flags)
                if found:
                    prefix, ent, topic = found
                    by_guid[(prefix, ent)] = topic
                    by_entity[ent].add(topic)
    return by_guid, by_entity


def topic_of(prefix, ent, by_guid, by_entity):
    if ent is None:
        return "unknown entity"
    if is_builtin(ent):
        return DISCOVERY
    if prefix is not None and (prefix, ent) in by_guid:
        return by_guid[(prefix, ent)]
    names = by_entity.get(ent, set())
    if len(names) == 1:
        return next(iter(names))
    return f"unannounced writer {ent:08x}" if not names else f"writer {ent:08x} ({' or '.join(sorted(names))})"


class Tally:
    def __init__(self):
        self.kind = collections.Counter()
        self.topic = collections.Counter()
        self.topic_kind = collections.defaultdict(collections.Counter)
        self.topic_dir = collections.defaultdict(collections.Counter)
        self.samples = collections.Counter()  # DATA / DATA_FRAG submessages of each topic
        # (writer prefix, writer entity, reader prefix, reader entity) -> submessage counts
        self.pairs = collections.defaultdict(collections.Counter)
        self.packets = 0
        self.total = 0


def attribute(p, by_guid, by_entity, tally, direction):
    tally.packets += 1
    tally.total += p.ip_len
    if not p.udp or p.payload[:4] != b"RTPS" or len(p.payload) < 20:
        tally.kind["not RTPS"] += p.ip_len
        tally.topic["not RTPS"] += p.ip_len
        tally.topic_kind["not RTPS"]["not RTPS"] += p.ip_len
        tally.topic_dir["not RTPS"][direction] += p.ip_len
        return
    source = p.payload[8:20].hex()
    dest = None
    shared = collections.Counter({"IP/UDP headers": p.ip_headers, "RTPS header": 20})
    # Bytes the snaplen cut off: counted as what they are not known to be.
    captured = p.ip_headers + len(p.payload)
    if p.ip_len > captured:
        shared["truncated"] += p.ip_len - captured
    owned = []  # (topic, kind, bytes)
    for sid, flags, body, size in submessages(p.payload):
        if sid is None:
            shared["truncated"] += size
            continue
        name = SUBMESSAGES.get(sid, f"submessage 0x{sid:02x}")
        if sid == 0x0E and len(body) >= 12:
            dest = body[:12].hex()
            if dest == "00" * 12:
                dest = None
        elif sid == 0x0C and len(body) >= 20:
            source = body[8:20].hex()
        if sid in (0x06, 0x07) and len(body) >= 8:
            reader, writer = entity(body, 0, flags), entity(body, 4, flags)
            if sid == 0x06:
                pair = tally.pairs[(dest, writer, source, reader)]
                pair["ACKNACK"] += 1
                if len(body) >= 20 and body[8:20] == b"\0" * 12:  # base 0.0, no bits
                    pair["pre-emptive"] += 1
            else:
                tally.pairs[(source, writer, dest, reader)]["HEARTBEAT"] += 1
        if sid in WRITER_OFFSET:
            at, sender_is_writer = WRITER_OFFSET[sid]
            topic = topic_of(source if sender_is_writer else dest, entity(body, at, flags), by_guid, by_entity)
            owned.append((topic, name, size))
            if sid in (0x15, 0x16):
                tally.samples[topic] += 1
        else:
            shared[name] += size
    for kind, size in list(shared.items()) + [(k, s) for _, k, s in owned]:
        tally.kind[kind] += size
    owners = collections.Counter()
    for topic, kind, size in owned:
        owners[topic] += size
        tally.topic[topic] += size
        tally.topic_kind[topic][kind] += size
        tally.topic_dir[topic][direction] += size
    overhead = sum(shared.values())
    if not owners:
        owners[DISCOVERY if not owned else owned[0][0]] = 1
    whole = sum(owners.values())
    given = 0
    for i, (topic, weight) in enumerate(sorted(owners.items())):
        part = overhead - given if i == len(owners) - 1 else overhead * weight // whole
        given += part
        tally.topic[topic] += part
        tally.topic_kind[topic][OVERHEAD] += part
        tally.topic_dir[topic][direction] += part


def window_of(args):
    if args.steps:
        marks = []
        with open(args.steps) as fh:
            lines = fh.read().splitlines()
        for n, line in enumerate(lines, 1):
            f = line.split()
            if len(f) != 3:
                raise ValueError(f"{args.steps}:{n}: expected 'NAME UPTIME EPOCH', got {line.strip()!r}")
            marks.append((f[0], float(f[2])))
        names = [m[0] for m in marks]
        if args.from_step not in names:
            raise ValueError(f"{args.steps}: no step '{args.from_step}' (steps: {', '.join(names)})")
        i = names.index(args.from_step)
        start = marks[i][1]
        if args.to_step:
            if args.to_step not in names[i + 1:]:
                raise ValueError(f"{args.steps}: no step '{args.to_step}' after '{args.from_step}'")
            end = marks[names.index(args.to_step, i + 1)][1]
        else:
            end = marks[i + 1][1] if i + 1 < len(marks) else None
        return start, end
    return args.start, args.end


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pcap")
    ap.add_argument("--steps", help="step marks of bench/fleet_link.sh --capture (steps-N)")
    ap.add_argument("--from", dest="from_step", help="the step the window starts at")
    ap.add_argument("--to", dest="to_step", help="the step it ends at (default: the next one)")
    ap.add_argument("--start", type=float, help="window start, s since the epoch")
    ap.add_argument("--end", type=float, help="window end, s since the epoch")
    ap.add_argument("--local", help="IP address prefix of this side (the ground): the direction columns")
    ap.add_argument("--title", default="", help="a line printed above the tables")
    ap.add_argument("--pairs", type=int, default=0, metavar="N",
                    help="also the N writer-reader pairs with the most HEARTBEATs and ACKNACKs")
    args = ap.parse_args(argv)
    if args.steps and not args.from_step:
        ap.error("--steps needs --from STEP")
    try:
        start, end = window_of(args)
        packets = list(datagrams(read_pcap(args.pcap)))
    except (OSError, ValueError) as e:
        print(f"rtps_breakdown.py: {e}", file=sys.stderr)
        return 2
    by_guid, by_entity = learn_topics(packets)
    timed = [p for p in packets if p.time is not None]
    if not timed:
        print(f"rtps_breakdown.py: {args.pcap}: no packets", file=sys.stderr)
        return 2
    start = timed[0].time if start is None else start
    end = timed[-1].time if end is None else end
    if end <= start:
        print(f"rtps_breakdown.py: the window ends ({end}) before it starts ({start})", file=sys.stderr)
        return 2
    tally = Tally()
    for p in timed:
        if start <= p.time < end:
            if args.local:
                direction = "sent" if p.src.startswith(args.local) else "received"
            else:
                direction = p.src
            attribute(p, by_guid, by_entity, tally, direction)
    print(render(tally, end - start, args, by_guid))
    return 0


def render(t, seconds, args, by_guid):
    rate = lambda b: f"{b / seconds:.0f}"
    share = lambda b: f"{100 * b / t.total:.1f} %" if t.total else "-"
    lines = []
    if args.title:
        lines += [args.title, ""]
    lines.append(f"{t.total} IP bytes in {seconds:.1f} s: {t.total / seconds:.0f} B/s ({8 * t.total / seconds / 1000:.1f} kbit/s), "
                 f"{t.packets / seconds:.1f} packets/s; {len(by_guid)} endpoints announced in the capture")
    lines += ["", "| kind | B/s | share |", "|---|---:|---:|"]
    for kind, b in sorted(t.kind.items(), key=lambda kv: -kv[1]):
        lines.append(f"| {kind} | {rate(b)} | {share(b)} |")
    dirs = sorted({d for c in t.topic_dir.values() for d in c})
    kinds = ["DATA", "DATA_FRAG", "HEARTBEAT", "ACKNACK", "GAP", OVERHEAD]
    other = lambda c: sum(v for k, v in c.items() if k not in kinds)
    lines += ["", "| topic | B/s | share | samples/s | " + " | ".join(f"{k} B/s" for k in kinds) + " | other B/s | "
              + " | ".join(f"{d} B/s" for d in dirs) + " |",
              "|---|---:|---:|---:|" + "---:|" * (len(kinds) + 1 + len(dirs))]
    for topic, b in sorted(t.topic.items(), key=lambda kv: -kv[1]):
        c = t.topic_kind[topic]
        lines.append(f"| {topic} | {rate(b)} | {share(b)} | {t.samples[topic] / seconds:.1f} | "
                     + " | ".join(rate(c[k]) for k in kinds) + f" | {rate(other(c))} | "
                     + " | ".join(rate(t.topic_dir[topic][d]) for d in dirs) + " |")
    lines.append(f"| total | {rate(t.total)} | 100 % | {sum(t.samples.values()) / seconds:.1f} | "
                 + " | ".join(rate(sum(t.topic_kind[x][k] for x in t.topic_kind)) for k in kinds)
                 + f" | {rate(sum(other(c) for c in t.topic_kind.values()))} | "
                 + " | ".join(rate(sum(t.topic_dir[x][d] for x in t.topic_dir)) for d in dirs) + " |")
    if args.pairs > 0:
        lines += ["", f"{len(t.pairs)} writer-reader pairs exchanged HEARTBEATs or ACKNACKs; the {args.pairs} busiest:", "",
                  "| writer | reader | HEARTBEAT/s | ACKNACK/s | of them pre-emptive/s |", "|---|---|---:|---:|---:|"]
        busiest = sorted(t.pairs.items(), key=lambda kv: (-(kv[1]["HEARTBEAT"] + kv[1]["ACKNACK"]), kv[0][0] or "", kv[0][2] or ""))
        for (wp, we, rp, re_), c in busiest[:args.pairs]:
            lines.append(f"| {endpoint_name(wp, we)} | {endpoint_name(rp, re_) if rp else 'every reader'} | "
                         f"{c['HEARTBEAT'] / seconds:.1f} | {c['ACKNACK'] / seconds:.1f} | {c['pre-emptive'] / seconds:.1f} |")
    return "\n".join(lines)


ENDPOINT_NAMES = {
    0x000100C2: "SPDP writer", 0x000100C7: "SPDP reader",
    0x000003C2: "SEDP publications writer", 0x000003C7: "SEDP publications reader",
    0x000004C2: "SEDP subscriptions writer", 0x000004C7: "SEDP subscriptions reader",
    0x000200C2: "participant message writer", 0x000200C7: "participant message reader",
}


def endpoint_name(prefix, ent):
    who = prefix[4:16] if prefix else "?"
    what = "?" if ent is None else ENDPOINT_NAMES.get(ent, f"{ent:08x}")
    return f"{who} {what}"


if __name__ == "__main__":
    sys.exit(main())
