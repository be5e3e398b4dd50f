// What a client that should not get in gets, against a viewer started with a token:
//   node security.mjs <ws port> <http port> <token> <max clients>
// Each check prints PASS/FAIL; exit 1 on any FAIL.
import WebSocket from "ws";
import http from "http";

const [wsPort, httpPort, token, maxClients] = process.argv.slice(2);
const base = `ws://127.0.0.1:${wsPort}/`;
let failed = 0;
const check = (ok, what) => { console.log(`${ok ? "PASS" : "FAIL"}: ${what}`); if (!ok) failed++; };

// Opens a WebSocket; resolves {open, status} once it opened or was refused.
function attempt(url, protocols, headers = {}) {
  return new Promise((resolve) => {
    const ws = new WebSocket(url, protocols, { headers });
    ws.on("open", () => resolve({ open: true, ws, protocol: ws.protocol }));
    ws.on("unexpected-response", (_req, res) => resolve({ open: false, status: res.statusCode }));
    ws.on("error", () => resolve({ open: false, status: 0 }));
  });
}
function get(path) {
  return new Promise((resolve) => {
    http.get({ host: "127.0.0.1", port: httpPort, path, agent: false }, (res) => {
      let body = ""; res.on("data", (d) => (body += d)); res.on("end", () => resolve({ status: res.statusCode, body }));
    }).on("error", () => resolve({ status: 0, body: "" }));
  });
}

const good = `${base}?token=${token}`;
let r = await attempt(base, ["foxglove.websocket.v1"]);
check(!r.open && r.status === 401, `no token: refused with 401 (got ${r.open ? "open" : r.status})`);
r = await attempt(`${base}?token=${"0".repeat(token.length)}`, ["foxglove.websocket.v1"]);
check(!r.open && r.status === 401, `a wrong token: refused with 401 (got ${r.open ? "open" : r.status})`);
r = await attempt(good, ["foxglove.websocket.v1"], { Origin: "http://evil.example" });
check(!r.open && r.status === 403, `a foreign Origin: refused with 403 (got ${r.open ? "open" : r.status})`);
r = await attempt(good, ["chat"]);
check(!r.open && r.status === 400, `no Foxglove subprotocol: refused with 400 (got ${r.open ? "open" : r.status})`);
for (const p of ["foxglove.sdk.v1", "foxglove.websocket.v1"]) {
  r = await attempt(good, [p]);
  check(r.open && r.protocol === p, `the token and ${p}: accepted, ${p} selected`);
  if (r.open) r.ws.close();
}
r = await attempt(good, ["foxglove.websocket.v1"], { Origin: `http://127.0.0.1:${httpPort}` });
check(r.open, "the page's own Origin: accepted");
if (r.open) r.ws.close();

// Garbage: the server answers with error statuses, then closes the connection.
r = await attempt(good, ["foxglove.websocket.v1"]);
if (r.open) {
  const closed = new Promise((resolve) => r.ws.on("close", (code) => resolve(code)));
  for (let i = 0; i < 30; ++i) r.ws.send(i % 2 ? "not json" : Buffer.from([0x07, 1, 2, 3]));
  const code = await Promise.race([closed, new Promise((res) => setTimeout(() => res("still open"), 5000))]);
  // 1008 when the close frame arrives before the rest of the garbage does, 1006 when it does not.
  check(code === 1008 || code === 1006, `30 garbage messages: the server closed the connection (${code})`);
}
// An oversized message: closed (message too big).
r = await attempt(good, ["foxglove.websocket.v1"]);
if (r.open) {
  const closed = new Promise((resolve) => r.ws.on("close", (code) => resolve(code)));
  r.ws.send("x".repeat(2 << 20));
  const code = await Promise.race([closed, new Promise((res) => setTimeout(() => res("still open"), 5000))]);
  check(code === 1009 || code === 1006, `a 2 MiB message: the server closed the connection (${code})`);
}
// Control is off: advertising a channel to publish on is refused with an error status.
r = await attempt(good, ["foxglove.websocket.v1"]);
if (r.open) {
  const status = new Promise((resolve) => r.ws.on("message", (d, binary) => {
    if (!binary) { const m = JSON.parse(d.toString()); if (m.op === "status") resolve(m); }
  }));
  r.ws.send(JSON.stringify({ op: "advertise", channels: [{ id: 1, topic: "/cmd_vel", encoding: "json", schemaName: "x" }] }));
  const m = await Promise.race([status, new Promise((res) => setTimeout(() => res(null), 3000))]);
  check(m && m.level === 2 && /control/.test(m.message), `client advertise with control off: error status (${m && m.message})`);
  r.ws.close();
}
// Too many clients: the one past max_clients is refused with 503.
const held = [];
for (let i = 0; i < Number(maxClients); ++i) {
  const a = await attempt(good, ["foxglove.websocket.v1"]);
  if (a.open) held.push(a.ws);
}
r = await attempt(good, ["foxglove.websocket.v1"]);
check(held.length === Number(maxClients) && !r.open && r.status === 503,
      `${maxClients} clients held, the next refused with 503 (held ${held.length}, got ${r.open ? "open" : r.status})`);
for (const w of held) w.close();

// The page's server serves its own files and nothing else.
let g = await get("/");
check(g.status === 200 && /<canvas/.test(g.body), `GET / : the page (${g.status})`);
g = await get("/viewer.js");
check(g.status === 200, `GET /viewer.js (${g.status})`);
for (const p of ["/../CMakeLists.txt", "/..%2f..%2fetc%2fpasswd", "/etc/passwd", "/schemas/Grid.json", "//web/index.html"]) {
  g = await get(p);
  check(g.status === 404, `GET ${p}: 404 (${g.status})`);
}
process.exit(failed ? 1 : 0);
