#!/usr/bin/env python3
"""canopen_feeder.py SERVICE CONFIG DOMAIN BUS_FILE [SERVICE OPTIONS...]

Runs pmu-service on a bus that is one end of a socketpair (`--bus fd:N`, struct can_frame
records, as the benchmarks drive it on a kernel without CAN) and, on the other end, is a
battery (MG BMS, node 2) and an MPPT (device 4) that send frames built from
spec/solar-boat-canopen-battery-mppt.txt's tables every 100 ms. The frames pass the
service's SocketCAN code and its receive filters (userspace for an adopted fd) as on a real
bus. Writes the service's bus name (fdN) to BUS_FILE once the service runs; stops the
service and exits on SIGTERM. cyclone_client --canopen-bus checks what arrives.
"""
import os
import signal
import socket
import struct
import subprocess
import sys
import time


def frame(cob_id, index, subindex, value):
    # Data[0] command byte, Data[1..2] index (little-endian), Data[3] subindex, Data[4..] value.
    data = bytes([0x43, index & 0xFF, index >> 8, subindex]) + bytes(value)
    # struct can_frame: can_id (u32, no flags: an 11-bit id), len (u8), 3 pad bytes, data[8].
    return struct.pack("<IB3x8s", cob_id, len(data), data.ljust(8, b"\0"))


FRAMES = [
    frame(0x302, 0x2005, 0x01, [0xFB, 0xBB]),              # voltage 48123 mV
    frame(0x302, 0x2005, 0x05, [87]),                      # state of charge 87 %
    frame(0x402, 0x2005, 0x0E, [0x78, 0x56, 0x34, 0x12]),  # BMS state 0x12345678
    frame(0x202, 0x0000, 0x00, [77]),                      # power level 77 %
    frame(0x482, 0x2000, 5, [0xE5, 0x0C]),                 # cell 5: 3301 mV
    frame(0x4E6 + 8 * 4, 0, 0x00, [0x9C, 0xFF]),           # MPPT 4 output voltage, -100 counts
    frame(0x4E6 + 8 * 4, 0, 0x04, [1]),                    # MPPT 4 safety enabled
    frame(0x4E6 + 8 * 4 + 1, 0, 0x02, [45]),               # MPPT 4 duty cycle panel 2, 45 %
]


def main():
    service, config, domain, bus_file = sys.argv[1:5]
    ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    fd = theirs.fileno()
    child = subprocess.Popen(
        [service, "--config", config, "--bus", f"fd:{fd}", "--domain", domain] + sys.argv[5:],
        pass_fds=(fd,))
    theirs.close()
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    with open(bus_file, "w") as f:
        f.write(f"fd{fd}\n")
    try:
        while not stop and child.poll() is None:
            for f in FRAMES:
                ours.send(f)
            time.sleep(0.1)
    except OSError:
        pass  # the service closed its end
    finally:
        if child.poll() is None:
            child.terminate()
            child.wait(timeout=10)
    return 0 if stop else 1


if __name__ == "__main__":
    sys.exit(main())
