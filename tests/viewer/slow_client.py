#!/usr/bin/env python3
"""A client that subscribes to every channel and then never reads, with a 4 KiB receive buffer so
the kernel cannot read for it: the server must drop its messages and then close it, while the run
goes on. Plain sockets, the WebSocket handshake by hand (RFC 6455).
    slow_client.py <ws url> <seconds>"""
import base64, json, os, socket, struct, sys, time
from urllib.parse import urlparse

url, seconds = sys.argv[1], float(sys.argv[2])
u = urlparse(url)
s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
s.connect((u.hostname, u.port))
key = base64.b64encode(os.urandom(16)).decode()
s.sendall((f"GET {u.path or '/'}{'?' + u.query if u.query else ''} HTTP/1.1\r\nHost: {u.hostname}:{u.port}\r\n"
           f"Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
           "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n").encode())
buf = b""
while b"\r\n\r\n" not in buf:
    buf += s.recv(4096)
assert b" 101 " in buf.split(b"\r\n")[0], buf[:200]

def send_text(text):
    data = text.encode()
    mask = os.urandom(4)
    header = bytes([0x81]) + (bytes([0x80 | len(data)]) if len(data) < 126 else bytes([0x80 | 126]) + struct.pack(">H", len(data)))
    s.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

# Subscribe to channels 1..32 (the server advertises fewer; unknown ones get an error status).
send_text(json.dumps({"op": "subscribe", "subscriptions": [{"id": i, "channelId": i} for i in range(1, 12)]}))
# Now read nothing; find out whether the server closed the connection.
end = time.time() + seconds
time.sleep(seconds)
s.setblocking(False)
closed = False
try:
    while True:
        chunk = s.recv(1 << 20)
        if not chunk:
            closed = True
            break
except BlockingIOError:
    pass
except ConnectionResetError:
    closed = True
print("slow client: " + ("closed by the server" if closed else "still open"))
