"""Raw WebSocket clients for tests/mcap/serve_test.sh, below what a library would hide.

  python3 ws_raw.py PORT no-subprotocol
      An opening handshake without Sec-WebSocket-Protocol; prints the server's status line.
  python3 ws_raw.py PORT origin ORIGIN
      An opening handshake offering foxglove.websocket.v1 from a page of ORIGIN (its Origin
      header); prints the server's status line.
  python3 ws_raw.py PORT sdk
      Offers foxglove.sdk.v1 alone; checks that the server chose it, that serverInfo lists the
      capability time, and that after subscribing to pmu/voltages a Time message comes before
      the first MessageData and is not older than it. Prints what it got; exit 1 otherwise.
  python3 ws_raw.py PORT slow SECONDS
      Offers foxglove.websocket.v1, reads serverInfo and advertise, subscribes to every
      advertised channel, then does not read its socket for SECONDS (a receive buffer of a
      few kB, so the server's writes back up at once) and closes. Prints what it subscribed.
"""
import base64
import json
import os
import socket
import struct
import sys
import time


def handshake(port, subprotocol, origin=None):
    s = socket.socket()
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # before connect: a small window
    s.connect(("127.0.0.1", port))
    key = base64.b64encode(os.urandom(16)).decode()
    lines = [
        "GET / HTTP/1.1",
        f"Host: 127.0.0.1:{port}",
        "Upgrade: websocket",
        "Connection: Upgrade",
        f"Sec-WebSocket-Key: {key}",
        "Sec-WebSocket-Version: 13",
    ]
    if subprotocol:
        lines.append(f"Sec-WebSocket-Protocol: {subprotocol}")
    if origin:
        lines.append(f"Origin: {origin}")
    s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(1)
        if not chunk:
            break
        head += chunk
    return s, head.decode(errors="replace")


def recv_exact(s, n):
    data = b""
    while len(data) < n:
        chunk = s.recv(n - len(data))
        if not chunk:
            raise EOFError("server closed")
        data += chunk
    return data


def read_frame(s):
    b0, b1 = recv_exact(s, 2)
    n = b1 & 0x7F
    if n == 126:
        n = struct.unpack(">H", recv_exact(s, 2))[0]
    elif n == 127:
        n = struct.unpack(">Q", recv_exact(s, 8))[0]
    return b0 & 0x0F, recv_exact(s, n)


def send_text(s, text):
    payload = text.encode()
    mask = os.urandom(4)
    header = bytes([0x81])
    n = len(payload)
    if n < 126:
        header += bytes([0x80 | n])
    else:
        header += bytes([0x80 | 126]) + struct.pack(">H", n)
    s.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))


def sdk(port):
    s, head = handshake(port, "foxglove.sdk.v1")
    lines = head.splitlines()
    if not lines or " 101 " not in lines[0]:
        sys.exit(f"handshake refused: {head}")
    if "sec-websocket-protocol: foxglove.sdk.v1" not in head.lower():
        sys.exit(f"the server did not choose foxglove.sdk.v1: {head}")
    s.settimeout(20)
    channels, capabilities, time_ns = None, None, None
    while channels is None:
        op, payload = read_frame(s)
        if op == 1:
            message = json.loads(payload)
            if message.get("op") == "serverInfo":
                capabilities = message.get("capabilities")
            elif message.get("op") == "advertise":
                channels = message["channels"]
        elif op == 2 and payload[0] == 2:
            time_ns = struct.unpack("<Q", payload[1:9])[0]
    if capabilities != ["time"]:
        sys.exit(f"serverInfo capabilities {capabilities}")
    voltages = [c["id"] for c in channels if c["topic"] == "pmu/voltages"]
    send_text(s, json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": voltages[0]}]}))
    while True:
        op, payload = read_frame(s)
        if op != 2:
            continue
        if payload[0] == 2:
            time_ns = struct.unpack("<Q", payload[1:9])[0]
        elif payload[0] == 1:
            sub, stamp = struct.unpack("<IQ", payload[1:13])
            if sub != 7:
                sys.exit(f"MessageData for subscription {sub}")
            if time_ns is None:
                sys.exit("MessageData before any Time message")
            if stamp > time_ns:
                sys.exit(f"MessageData stamped {stamp}, after the server's time {time_ns}")
            print(f"sdk client: foxglove.sdk.v1, capabilities {capabilities}, time {time_ns}, "
                  f"voltages stamped {stamp}")
            return


def main():
    port, mode = int(sys.argv[1]), sys.argv[2]
    if mode == "no-subprotocol":
        s, head = handshake(port, None)
        print(head.splitlines()[0] if head else "(no answer)")
        return
    if mode == "origin":
        s, head = handshake(port, "foxglove.websocket.v1", sys.argv[3])
        print(head.splitlines()[0] if head else "(no answer)")
        return
    if mode == "sdk":
        sdk(port)
        return
    s, head = handshake(port, "foxglove.websocket.v1")
    if " 101 " not in head.splitlines()[0]:
        sys.exit(f"handshake refused: {head}")
    channels = None
    while channels is None:
        op, payload = read_frame(s)
        if op == 1:
            message = json.loads(payload)
            if message.get("op") == "advertise":
                channels = message["channels"]
    send_text(s, json.dumps({"op": "subscribe",
                             "subscriptions": [{"id": i, "channelId": c["id"]} for i, c in enumerate(channels)]}))
    print(f"slow client: subscribed to {len(channels)} channels; not reading for {sys.argv[3]} s", flush=True)
    time.sleep(float(sys.argv[3]))
    s.close()


main()
