// Foxglove's own protocol client (@foxglove/ws-protocol) against mbot_nav's viewer: it connects,
// subscribes to every advertised channel and validates each message against the schema that
// Foxglove's npm package @foxglove/schemas ships (not the server's copy), for a while.
//   node foxglove_client.mjs <ws url> <seconds> <report.json> [required topic ...]
// Exits 1 when a message fails its schema, a required topic sent nothing, or the server's
// advertised schema is not Foxglove's.
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";
import Ajv from "ajv";
import { createRequire } from "module";
import { writeFileSync } from "fs";

const require = createRequire(import.meta.url);
const { FoxgloveClient } = wsProtocol;
const foxgloveSchemas = require("@foxglove/schemas/jsonschema");

const [url, seconds, reportPath, ...required] = process.argv.slice(2);
const ajv = new Ajv({ strict: false, allErrors: false });
const validators = new Map();  // channel id -> {topic, validate}
const report = { url, subprotocol: null, serverInfo: null, channels: [], messages: {}, bytes: {}, invalid: [],
                 schemaMismatch: [], time_messages: 0, last_time_ns: 0, errors: [] };

// The client's own subprotocol (foxglove.websocket.v1), or SUBPROTOCOL=foxglove.sdk.v1 as current Foxglove asks.
const ws = new WebSocket(url, [process.env.SUBPROTOCOL || FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const decoder = new TextDecoder();

client.on("open", () => { report.subprotocol = ws.protocol; });
client.on("error", (e) => report.errors.push(String(e && e.message || e)));
client.on("serverInfo", (info) => { report.serverInfo = info; });
client.on("advertise", (channels) => {
  for (const c of channels) {
    report.channels.push({ id: c.id, topic: c.topic, encoding: c.encoding, schemaName: c.schemaName });
    let schema;
    if (c.schemaName.startsWith("foxglove.")) {
      schema = foxgloveSchemas[c.schemaName.slice("foxglove.".length)];
      if (!schema) { report.schemaMismatch.push(`${c.topic}: ${c.schemaName} is not one of Foxglove's schemas`); continue; }
      const advertised = JSON.parse(c.schema);
      if (JSON.stringify(advertised) !== JSON.stringify(schema)) {
        report.schemaMismatch.push(`${c.topic}: the advertised ${c.schemaName} differs from @foxglove/schemas'`);
      }
    } else {
      schema = JSON.parse(c.schema);  // the project's own types: their advertised schema
    }
    validators.set(c.id, { topic: c.topic, validate: ajv.compile(schema) });
    const sub = client.subscribe(c.id);
    validators.set(`sub${sub}`, validators.get(c.id));
  }
});
client.on("message", ({ subscriptionId, data }) => {
  const v = validators.get(`sub${subscriptionId}`);
  if (!v) { report.errors.push(`message on unknown subscription ${subscriptionId}`); return; }
  report.messages[v.topic] = (report.messages[v.topic] || 0) + 1;
  report.bytes[v.topic] = (report.bytes[v.topic] || 0) + data.byteLength;
  let msg;
  try { msg = JSON.parse(decoder.decode(data)); } catch (e) { report.invalid.push(`${v.topic}: not JSON`); return; }
  if (!v.validate(msg) && report.invalid.length < 20) {
    report.invalid.push(`${v.topic}: ${ajv.errorsText(v.validate.errors)}`);
  }
});
client.on("time", ({ timestamp }) => { report.time_messages++; report.last_time_ns = Number(timestamp); });

setTimeout(() => {
  client.close();
  const missing = required.filter((t) => !report.messages[t]);
  report.missing = missing;
  writeFileSync(reportPath, JSON.stringify(report, null, 2));
  console.log(`subprotocol ${report.subprotocol}; ${report.channels.length} channels; messages ${JSON.stringify(report.messages)}`);
  for (const line of [...report.invalid, ...report.schemaMismatch, ...report.errors]) console.log("FAIL: " + line);
  if (missing.length) console.log("FAIL: nothing on " + missing.join(", "));
  const wanted = process.env.SUBPROTOCOL || FoxgloveClient.SUPPORTED_SUBPROTOCOL;
  if (report.subprotocol !== wanted) console.log(`FAIL: subprotocol ${report.subprotocol}, not ${wanted}`);
  const ok = report.subprotocol === wanted && !report.invalid.length && !report.schemaMismatch.length && !missing.length;
  process.exit(ok ? 0 : 1);
}, Number(seconds) * 1000);
