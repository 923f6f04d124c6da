#!/usr/bin/env python3
"""Writes the seed corpus of fuzz_command_path: one file per scenario, each a sequence of
[length: u16 LE][CDR payload of a pmu::v5::Command] records (idl/command.idl's field order, little-
endian CDR with its 4-byte encapsulation header). Run from the repository root."""
import os
import struct


def cdr(rid, bus, addr, kind, param, value, outputs=0, enable=0, groups=0, expires=0, confirm=0):
    b = bytearray()

    def align(n):
        while len(b) % n:
            b.append(0)

    def string(s):
        s = s.encode()
        align(4)
        b.extend(struct.pack('<I', len(s) + 1))
        b.extend(s)
        b.append(0)

    string(rid)
    string(bus)
    align(2)
    b.extend(struct.pack('<H', addr))
    align(4)
    b.extend(struct.pack('<I', kind))
    string(param)
    align(8)
    b.extend(struct.pack('<d', value))
    b.extend(bytes([outputs, enable, groups]))  # booleans are bytes: any value may be sent
    align(8)
    b.extend(struct.pack('<Q', expires))
    b.append(confirm)
    return bytes([0, 1, 0, 0]) + bytes(b)


def records(*payloads):
    return b''.join(struct.pack('<H', len(p)) + p for p in payloads)


# kinds: 0 GET, 1 SET_PARAMETER, 2 SET_OUTPUTS, 3 ENABLE, 4 DISABLE, 5 SET_GENERATION,
# 6 REQUEST_MEASUREMENTS, 7 ENGINE_START, 8 ENGINE_STOP, 9 RESET, 10 GET_SERIAL, 11 GET_FIRMWARE
SEEDS = {
    'get_voltage': records(cdr('g1', 'sim0', 1, 0, 'avionics_voltage', 0)),
    'get_groups': records(cdr('g2', 'sim0', 1, 0, 'voltages', 0), cdr('g3', 'sim0', 2, 0, 'outputs', 0)),
    'set_voltage': records(cdr('s1', 'sim0', 1, 1, 'avionics_voltage', 20.0)),
    'set_tu_round': records(cdr('s2', 'sim0', 1, 1, 'upper_temperature_limit', 0.0005)),
    'set_s0_confirm': records(cdr('s3', 'sim0', 1, 1, 'power_up_state', 1.0, confirm=1)),
    'set_address': records(cdr('s4', 'sim0', 2, 1, 'can_address', 7.0, confirm=1)),
    'outputs': records(cdr('o1', 'sim0', 1, 2, '', 0, outputs=0x0F), cdr('o2', 'sim0', 1, 3, '', 0, outputs=0x02),
                       cdr('o3', 'sim0', 1, 4, '', 0, outputs=0x01, confirm=1)),
    'generation': records(cdr('gen', 'sim0', 1, 5, '', 0, enable=1)),
    'measure_old_fw': records(cdr('m1', 'sim0', 2, 6, '', 0, groups=0x03), cdr('m2', 'sim0', 1, 6, '', 0)),
    'engine': records(cdr('e1', 'sim0', 1, 7, '', 0, confirm=1), cdr('e2', 'sim0', 65535, 8, '', 0)),
    'reset': records(cdr('r1', 'sim0', 1, 9, '', 0, confirm=1)),
    'identity': records(cdr('i1', 'sim0', 1, 10, '', 0), cdr('i2', 'sim0', 2, 11, '', 0)),
    'duplicate': records(*[cdr('d1', 'sim0', 1, 1, 'payload_voltage', 20.0)] * 3),
    'reused': records(cdr('u1', 'sim0', 1, 1, 'payload_voltage', 20.0), cdr('u1', 'sim0', 1, 1, 'payload_voltage', 19.0),
                      cdr('u1', 'sim0', 1, 1, 'payload_voltage', 19.0)),
    'bad_bool': records(cdr('b1', 'sim0', 1, 7, '', 0, confirm=2)),
    'bad_kind': records(cdr('k1', 'sim0', 1, 99, '', 0)),
    'expiry_edges': records(cdr('x1', 'sim0', 1, 10, '', 0, expires=1 << 63),
                            cdr('x2', 'sim0', 1, 10, '', 0, expires=(1 << 64) - 1),
                            cdr('x3', 'sim0', 1, 10, '', 0, expires=1)),
    'log_injection': records(cdr('a\n\x1b[2Jaudit: FORGED', 'sim0', 1, 0, 'volts\nx', 0)),
    'unknown_bus': records(cdr('n1', 'can9', 1, 10, '', 0), cdr('', 'sim0', 1, 10, '', 0)),
}

if __name__ == '__main__':
    out = 'tests/fuzz/corpus/fuzz_command_path'
    os.makedirs(out, exist_ok=True)
    for name, data in SEEDS.items():
        with open(os.path.join(out, name), 'wb') as f:
            f.write(data)
