#!/usr/bin/env python3
"""A serial line for end_to_end.sh's serial run: a pty pair whose slave pmu-mavlink opens
with --serial, its master relayed to the ground station's UDP port (node-mavlink reads a
byte stream from either, and its splitter reassembles frames across chunks).
  pty_relay.py PTYFILE PORTFILE
Writes the slave's path to PTYFILE once open; bytes from the master go to 127.0.0.1:PORT
(PORT read from PORTFILE), datagrams coming back are written to the master. Runs until killed.
"""
import os
import select
import socket
import sys
import tty

pty_file, port_file = sys.argv[1:3]
port = int(open(port_file).read())
master, slave = os.openpty()
# Raw from the start: a fresh pty echoes and translates bytes until pmu-mavlink opens it and
# makes it raw itself. The slave stays open here, so the master never reads EIO meanwhile.
tty.setraw(slave)
sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
sock.bind(("127.0.0.1", 0))
with open(pty_file + ".tmp", "w") as f:
    f.write(os.ttyname(slave))
os.rename(pty_file + ".tmp", pty_file)
while True:
    readable, _, _ = select.select([master, sock], [], [])
    if master in readable:
        sock.sendto(os.read(master, 4096), ("127.0.0.1", port))
    if sock in readable:
        data = memoryview(sock.recv(65536))
        while data:
            data = data[os.write(master, data):]
