// The mbot_nav page: a Foxglove WebSocket client (the same protocol Foxglove speaks) drawing the
// map, the robot, the lidar, the particles, the path, the frontiers and (on request) the obstacle
// distances on a canvas, with the mission's state and the referee's score. No build step, no library.
"use strict";

const state = {
  connected: false,
  capabilities: [],
  channels: new Map(),   // channel id -> {topic, schemaName}
  subs: new Map(),       // subscription id -> topic
  counts: {},            // messages received per topic (the tests read them)
  time_ns: 0,
  map: null, mapImage: null, pose: null, odom: null, scan: null, particles: null, path: null,
  lidarMount: { x: 0, y: 0, theta: 0 }, mapToOdom: null,
  mission: null, slam: null, goal: null, framesDrawn: 0, metadata: {},
  frontiers: null, distances: null, distanceImage: null, showDistances: false, score: null,
  // Scan to screen: for each scan drawn, how long after the pipeline offered it to the viewer [ms].
  pendingScan: null, latencies: [],
};
window.mbotViewer = state;

const canvas = document.getElementById("view");
const ctx = canvas.getContext("2d");
const params = new URLSearchParams(location.search);
const token = params.get("token") || "";
let ws = null;

function yawOf(q) { return 2 * Math.atan2(q.z, q.w); }
function pose2d(p) { return { x: p.position.x, y: p.position.y, theta: yawOf(p.orientation) }; }
function compose(a, b) {
  const c = Math.cos(a.theta), s = Math.sin(a.theta);
  return { x: a.x + c * b.x - s * b.y, y: a.y + s * b.x + c * b.y, theta: a.theta + b.theta };
}

function onMessage(topic, msg) {
  state.counts[topic] = (state.counts[topic] || 0) + 1;
  switch (topic) {
    case "/map": state.map = msg; state.mapImage = null; break;
    case "/pose": state.pose = pose2d(msg.pose); break;
    case "/odom": state.odom = pose2d(msg.pose); break;
    case "/scan": state.scan = msg; state.pendingScan = null; break;
    case "/scan_stamp": state.pendingScan = msg.offered_wall_us; break;
    case "/obstacle_distance": state.distances = msg; state.distanceImage = null; break;
    case "/score": state.score = msg; break;
    case "/scene":
      for (const e of msg.entities) {
        if (e.id === "frontiers") state.frontiers = { cells: e.cubes.map((c) => c.pose.position), size: e.cubes.length ? e.cubes[0].size.x : 0.05, centroids: e.spheres.map((c) => c.pose.position) };
      }
      break;
    case "/particles": state.particles = msg.poses.map(pose2d); break;
    case "/path": state.path = msg.poses.map(pose2d); break;
    case "/mission": state.mission = msg; break;
    case "/slam_status": state.slam = msg; break;
    case "/tf":
      for (const t of msg.transforms) {
        const p = { x: t.translation.x, y: t.translation.y, theta: yawOf(t.rotation) };
        if (t.child_frame_id === "lidar") state.lidarMount = p;
        if (t.parent_frame_id === "map" && t.child_frame_id === "odom") state.mapToOdom = p;
      }
      break;
  }
}

function connect(wsPort) {
  const url = `ws://${location.hostname}:${wsPort}/` + (token ? `?token=${encodeURIComponent(token)}` : "");
  ws = new WebSocket(url, ["foxglove.sdk.v1", "foxglove.websocket.v1"]);
  ws.binaryType = "arraybuffer";
  const decoder = new TextDecoder();
  ws.onopen = () => { state.connected = true; setLink(`connected (${ws.protocol})`, true); };
  ws.onclose = () => { state.connected = false; setLink("disconnected: retrying", false); setTimeout(() => connect(wsPort), 1000); };
  ws.onmessage = (ev) => {
    if (typeof ev.data === "string") {
      const m = JSON.parse(ev.data);
      if (m.op === "serverInfo") { state.capabilities = m.capabilities; state.metadata = m.metadata || {}; setupControl(); }
      else if (m.op === "advertise") {
        const subscriptions = [];
        for (const c of m.channels) {
          state.channels.set(c.id, c);
          state.subs.set(c.id, c.topic);
          subscriptions.push({ id: c.id, channelId: c.id });
        }
        ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
      } else if (m.op === "status") { console.log("server:", m.message); }
      return;
    }
    const view = new DataView(ev.data);
    const op = view.getUint8(0);
    if (op === 1) {
      const topic = state.subs.get(view.getUint32(1, true));
      const payload = decoder.decode(new Uint8Array(ev.data, 13));
      if (topic) onMessage(topic, JSON.parse(payload));
    } else if (op === 2) {
      state.time_ns = Number(view.getBigUint64(1, true));
    }
  };
}

function setLink(text, good) {
  const el = document.getElementById("link");
  el.textContent = text; el.className = good ? "good" : "bad";
}

// ---- drawing -------------------------------------------------------------------------------------
let view = { scale: 50, cx: 0, cy: 0 };  // pixels per metre, world point at the canvas centre

function fitView() {
  const m = state.map;
  if (!m) return;
  const w = m.column_count * m.cell_size.x, h = (atob(m.data).length / m.row_stride) * m.cell_size.y;
  view.scale = Math.min(canvas.width / (w * 1.05), canvas.height / (h * 1.05));
  view.cx = m.pose.position.x + w / 2;
  view.cy = m.pose.position.y + h / 2;
}
function toScreen(x, y) { return [canvas.width / 2 + (x - view.cx) * view.scale, canvas.height / 2 - (y - view.cy) * view.scale]; }
window.mbotToScreen = toScreen;  // the tests click on world points
function toWorld(px, py) { return [view.cx + (px - canvas.width / 2) / view.scale, view.cy - (py - canvas.height / 2) / view.scale]; }

// A foxglove.Grid of one byte per cell as an image: `colour(byte)` gives [r, g, b, a]. Row 0 is
// the lowest y: the image's last row.
function gridImage(m, colour) {
  const bytes = atob(m.data);
  const cols = m.column_count, rows = bytes.length / m.row_stride;
  const off = document.createElement("canvas");
  off.width = cols; off.height = rows;
  const img = off.getContext("2d").createImageData(cols, rows);
  for (let r = 0; r < rows; ++r) {
    for (let c = 0; c < cols; ++c) {
      img.data.set(colour(bytes.charCodeAt(r * m.row_stride + c)), ((rows - 1 - r) * cols + c) * 4);
    }
  }
  off.getContext("2d").putImageData(img, 0, 0);
  return { canvas: off, cols, rows };
}

// The map: ROS occupancy (int8: -1 unknown grey, 0 free white … 100 occupied black).
function mapImage() {
  return gridImage(state.map, (b) => {
    const v = b > 127 ? b - 256 : b;
    const g = v < 0 ? 128 : Math.round(255 - 2.55 * v);
    return [g, g, g, 255];
  });
}

// The obstacle distances (cm) as a colour ramp: red at the walls to clear at 0.5 m and beyond.
function distanceImage() {
  return gridImage(state.distances, (cm) => {
    const t = Math.min(1, cm / 50);
    return [230, Math.round(60 + 150 * t), 40, cm === 0 ? 0 : Math.round(170 * (1 - t))];
  });
}

function drawGrid(m, im) {
  const [x0, y1] = toScreen(m.pose.position.x, m.pose.position.y + im.rows * m.cell_size.y);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(im.canvas, x0, y1, im.cols * m.cell_size.x * view.scale, im.rows * m.cell_size.y * view.scale);
}

function percentile(values, p) {
  if (!values.length) return NaN;
  const sorted = [...values].sort((a, b) => a - b);
  return sorted[Math.min(sorted.length - 1, Math.floor(p * sorted.length))];
}
window.mbotLatency = () => ({ n: state.latencies.length, p50_ms: percentile(state.latencies, 0.5), p99_ms: percentile(state.latencies, 0.99) });

function robotPose() {
  if (state.pose) return state.pose;
  if (state.odom) return state.mapToOdom ? compose(state.mapToOdom, state.odom) : state.odom;
  return null;
}

function draw() {
  if (canvas.width !== canvas.clientWidth || canvas.height !== canvas.clientHeight) {
    canvas.width = canvas.clientWidth; canvas.height = canvas.clientHeight; state.mapImage = null;
  }
  ctx.fillStyle = "#3a3b3f"; ctx.fillRect(0, 0, canvas.width, canvas.height);
  if (state.map) {
    if (!state.mapImage) { fitView(); state.mapImage = mapImage(); }
    drawGrid(state.map, state.mapImage);
  }
  if (state.showDistances && state.distances) {
    if (!state.distanceImage) state.distanceImage = distanceImage();
    drawGrid(state.distances, state.distanceImage);
  }
  if (state.frontiers) {
    const f = state.frontiers, px = Math.max(2, f.size * view.scale);
    ctx.fillStyle = "rgba(242, 140, 0, 0.85)";
    for (const c of f.cells) { const [x, y] = toScreen(c.x, c.y); ctx.fillRect(x - px / 2, y - px / 2, px, px); }
    ctx.strokeStyle = "#d40"; ctx.lineWidth = 2;
    for (const c of f.centroids) { const [x, y] = toScreen(c.x, c.y); ctx.beginPath(); ctx.arc(x, y, 5, 0, 2 * Math.PI); ctx.stroke(); }
  }
  if (state.particles) {
    ctx.fillStyle = "#f90";
    for (const p of state.particles) { const [x, y] = toScreen(p.x, p.y); ctx.fillRect(x - 1, y - 1, 2, 2); }
  }
  if (state.path && state.path.length) {
    ctx.strokeStyle = "#2d2"; ctx.lineWidth = 2; ctx.beginPath();
    state.path.forEach((p, i) => { const [x, y] = toScreen(p.x, p.y); i ? ctx.lineTo(x, y) : ctx.moveTo(x, y); });
    ctx.stroke();
  }
  const robot = robotPose();
  if (robot && state.scan) {
    const s = state.scan, n = s.ranges.length, lidar = compose(robot, state.lidarMount);
    ctx.fillStyle = "#f33";
    for (let i = 0; i < n; ++i) {
      const r = s.ranges[i];
      if (!(r > 0)) continue;
      const a = s.start_angle + (n > 1 ? i * (s.end_angle - s.start_angle) / (n - 1) : 0);
      const p = compose(lidar, { x: r * Math.cos(a), y: r * Math.sin(a), theta: 0 });
      const [x, y] = toScreen(p.x, p.y); ctx.fillRect(x - 1.5, y - 1.5, 3, 3);
    }
  }
  if (state.goal) {
    const [x, y] = toScreen(state.goal.x, state.goal.y);
    ctx.strokeStyle = "#2f2"; ctx.lineWidth = 2; ctx.beginPath(); ctx.arc(x, y, 8, 0, 2 * Math.PI); ctx.stroke();
  }
  if (robot) {
    const [x, y] = toScreen(robot.x, robot.y), r = Math.max(4, 0.1 * view.scale);
    ctx.fillStyle = "#27f"; ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI); ctx.fill();
    ctx.strokeStyle = "#fff"; ctx.lineWidth = 2; ctx.beginPath(); ctx.moveTo(x, y);
    ctx.lineTo(x + r * Math.cos(robot.theta), y - r * Math.sin(robot.theta)); ctx.stroke();
  }
  document.getElementById("clock").textContent = (state.time_ns / 1e9).toFixed(1) + " s";
  if (state.mission) {
    document.getElementById("mission").textContent = state.mission.state;
    document.getElementById("detail").textContent = state.mission.detail;
  }
  if (state.slam) {
    document.getElementById("slam").textContent = `${state.slam.mode}, ${state.slam.state}` +
      (state.slam.mapping_on ? "" : ", not mapping") + (state.slam.localization_on ? "" : ", odometry only");
    document.getElementById("mapping").textContent = state.slam.mapping_on ? "stop mapping" : "start mapping";
    document.getElementById("localization").textContent = state.slam.localization_on ? "stop localization" : "start localization";
  }
  if (state.score) {
    const s = state.score;
    document.getElementById("score").textContent = `${s.points} / ${s.max_points}` + (s.collisions ? `, ${s.collisions} collisions` : "");
    document.getElementById("score").title = s.items.map((i) => `${i.name}: ${i.points} / ${i.max_points} (${i.detail})`).join("\n");
  }
  // The scan just drawn: how long since the pipeline offered it (the same machine's clock).
  if (state.scan && state.pendingScan !== null) {
    const ms = performance.timeOrigin + performance.now() - state.pendingScan / 1000;
    state.latencies.push(ms);
    if (state.latencies.length > 5000) state.latencies.shift();
    state.pendingScan = null;
    document.getElementById("lag").textContent = `${percentile(state.latencies.slice(-100), 0.5).toFixed(0)} ms`;
  }
  state.framesDrawn++;
  requestAnimationFrame(draw);
}

// ---- control (only when the server offers clientPublish) -----------------------------------------
const kGoalChannel = 1, kTwistChannel = 2, kPlaybackChannel = 3, kSlamChannel = 4, kMaxSpeed = 0.25, kMaxTurn = 1.5;
const keys = new Set();

function publish(channel, msg) {
  if (!ws || ws.readyState !== 1) return;
  const body = new TextEncoder().encode(JSON.stringify(msg));
  const frame = new Uint8Array(5 + body.length);
  frame[0] = 1; new DataView(frame.buffer).setUint32(1, channel, true); frame.set(body, 5);
  ws.send(frame);
}

function setupControl() {
  const on = state.capabilities.includes("clientPublish");
  document.getElementById("drive").textContent = on ? "control on" : "view only";
  if (!on) return;
  const channels = [
    { id: kGoalChannel, topic: "/goal_pose", encoding: "json", schemaName: "foxglove.PoseInFrame" },
    { id: kTwistChannel, topic: "/cmd_vel", encoding: "json", schemaName: "mbot.Twist" },
    { id: kSlamChannel, topic: "/slam_control", encoding: "json", schemaName: "mbot.SlamControl" }];
  const recording = state.metadata.playback === "true";
  if (recording) channels.push({ id: kPlaybackChannel, topic: "/playback", encoding: "json", schemaName: "mbot.Playback" });
  ws.send(JSON.stringify({ op: "advertise", channels }));
  document.getElementById("playback").hidden = !recording;
  document.getElementById("slam_buttons").hidden = false;
}

// SLAM's switches: what the button asks is the opposite of what /slam_status says holds.
document.getElementById("mapping").onclick = () => {
  publish(kSlamChannel, { mapping: !(state.slam ? state.slam.mapping_on : true) });
};
document.getElementById("localization").onclick = () => {
  publish(kSlamChannel, { localization: !(state.slam ? state.slam.localization_on : true) });
};
document.getElementById("clear_map").onclick = () => publish(kSlamChannel, { clear_map: true });

// A recording's pace: pause / play, and the speed (0: as fast as it can).
state.paused = false;
function sendPlayback() {
  publish(kPlaybackChannel, { paused: state.paused, speed: Number(document.getElementById("speed").value) });
  document.getElementById("pause").textContent = state.paused ? "play" : "pause";
}
document.getElementById("pause").onclick = () => { state.paused = !state.paused; sendPlayback(); };
document.getElementById("speed").onchange = sendPlayback;

function twist() {
  let v = 0, w = 0;
  if (keys.has("w")) v += kMaxSpeed;
  if (keys.has("s")) v -= kMaxSpeed;
  if (keys.has("a")) w += kMaxTurn;
  if (keys.has("d")) w -= kMaxTurn;
  return { linear: { x: v, y: 0, z: 0 }, angular: { x: 0, y: 0, z: w } };
}

canvas.addEventListener("click", (ev) => {
  if (!state.capabilities.includes("clientPublish")) return;
  const rect = canvas.getBoundingClientRect();
  const [x, y] = toWorld(ev.clientX - rect.left, ev.clientY - rect.top);
  state.goal = { x, y };
  publish(kGoalChannel, { timestamp: { sec: 0, nsec: 0 }, frame_id: "map",
    pose: { position: { x, y, z: 0 }, orientation: { x: 0, y: 0, z: 0, w: 1 } } });
});
window.addEventListener("keydown", (ev) => {
  const k = ev.key.toLowerCase();
  if ("wasd".includes(k) && k.length === 1) { keys.add(k); publish(kTwistChannel, twist()); }
});
window.addEventListener("keyup", (ev) => {
  const k = ev.key.toLowerCase();
  if (keys.delete(k)) publish(kTwistChannel, twist());  // released: the twist without it (zero when none)
});
window.addEventListener("blur", () => { keys.clear(); publish(kTwistChannel, twist()); });
// Held keys repeat the twist at 10 Hz: the server stops the robot when they stop coming (dead man).
setInterval(() => { if (keys.size) publish(kTwistChannel, twist()); }, 100);

// ---- saving the map --------------------------------------------------------------------------------
function download(name, blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob); a.download = name; a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}
document.getElementById("save_pgm").onclick = () => {
  const m = state.map; if (!m) return;
  const bytes = atob(m.data), cols = m.column_count, rows = bytes.length / m.row_stride;
  const header = `P5\n${cols} ${rows}\n255\n`;
  const pgm = new Uint8Array(header.length + cols * rows);
  for (let i = 0; i < header.length; ++i) pgm[i] = header.charCodeAt(i);
  for (let r = 0; r < rows; ++r) {
    for (let c = 0; c < cols; ++c) {
      let v = bytes.charCodeAt(r * m.row_stride + c); if (v > 127) v -= 256;
      // map_server's trinary: 0 occupied, 254 free, 205 unknown; the PGM's first row is the top.
      pgm[header.length + (rows - 1 - r) * cols + c] = v < 0 ? 205 : v >= 65 ? 0 : v <= 25 ? 254 : 205;
    }
  }
  download("map.pgm", new Blob([pgm], { type: "image/x-portable-graymap" }));
  const yaml = `image: map.pgm\nmode: trinary\nresolution: ${m.cell_size.x}\n` +
    `origin: [${m.pose.position.x}, ${m.pose.position.y}, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n`;
  download("map.yaml", new Blob([yaml], { type: "text/yaml" }));
};
document.getElementById("save_png").onclick = () => {
  if (!state.mapImage && state.map) state.mapImage = mapImage();
  if (state.mapImage) state.mapImage.canvas.toBlob((b) => download("map.png", b), "image/png");
};

document.getElementById("show_distances").onchange = (ev) => { state.showDistances = ev.target.checked; };

fetch("config.json").then((r) => r.json()).then((c) => connect(c.ws_port)).catch(() => connect(8765));
requestAnimationFrame(draw);
