"""Raw WebSocket clients for tests/mcap/serve_test.sh, below what a library would hide.

  python3 ws_raw.py PORT no-subprotocol
      An opening handshake without Sec-WebSocket-Protocol; prints the server's status line.
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


def handshake(port, subprotocol):
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


def main():
    port, mode = int(sys.argv[1]), sys.argv[2]
    if mode == "no-subprotocol":
        s, head = handshake(port, None)
        print(head.splitlines()[0] if head else "(no answer)")
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
