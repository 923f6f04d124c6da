// A Foxglove WebSocket client (@foxglove/ws-protocol's FoxgloveClient on `ws`) that reads the
// ROS 2 channels of `pmuctl serve` as Foxglove does: a channel of schemaEncoding ros2msg is
// parsed by @foxglove/rosmsg and decoded by @foxglove/rosmsg2-serialization's MessageReader.
// pmu-service runs with `vehicle: uav1` and `ros2: {enabled: true}` on the simulated power
// system (bus sim0: PMU 1, BMS node 2).
//
//   node serve_ros2_client.mjs URL late|early SECONDS
// Subscribes to every ROS 2 channel as it is advertised and waits until /diagnostics (with
// the statuses of uav1/sim0/pmu_1 and uav1/sim0/bms_2) and the three battery topics have each
// given a message that decodes, at most SECONDS. `early`: the client connects before the
// service runs, so the ROS 2 channels must come in an advertise after the first. `late`:
// they must be in the first advertise, and the first /diagnostics message must be the one
// written before the subscription (the server keeps it, as the DDS writer does for a latched
// subscriber).
// Exit status 0 when every check passed; 1 with the problems on stderr.
import wsProtocol from "@foxglove/ws-protocol"; // CommonJS: no named exports
const { FoxgloveClient } = wsProtocol;
import { parse as parseRosmsg } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const [url, when, seconds] = process.argv.slice(2);
const problems = [];
const problem = (p) => problems.push(p);
const want = {
  "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
  "/uav1/sim0/pmu_1/battery_a": "sensor_msgs/msg/BatteryState",
  "/uav1/sim0/pmu_1/battery_b": "sensor_msgs/msg/BatteryState",
  "/uav1/sim0/bms_2/battery": "sensor_msgs/msg/BatteryState",
};

const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const subscriptions = new Map(); // subscription id -> channel
const good = new Set(); // topics with a message that decoded as checked
let advertisements = 0;
let firstAdvertised = [];
let diagnosticsSubscribedAt = null;
let firstDiagnosticsStampMs = null;

client.on("error", (e) => problem(`client error: ${e.message ?? e}`));
client.on("advertise", (list) => {
  advertisements++;
  if (advertisements === 1) firstAdvertised = list.map((c) => c.topic);
  for (const c of list) {
    if (!(c.topic in want)) continue;
    if (c.encoding !== "cdr" || c.schemaEncoding !== "ros2msg" || c.schemaName !== want[c.topic]) {
      problem(`${c.topic}: ${c.encoding}/${c.schemaEncoding} ${c.schemaName}`);
      continue;
    }
    let reader;
    try {
      reader = new MessageReader(parseRosmsg(c.schema, { ros2: true }));
    } catch (e) {
      problem(`${c.topic}: schema does not parse: ${e.message}`);
      continue;
    }
    if (c.topic === "/diagnostics") diagnosticsSubscribedAt = Date.now();
    subscriptions.set(client.subscribe(c.id), { ...c, reader });
  }
});
client.on("message", ({ subscriptionId, data }) => {
  const c = subscriptions.get(subscriptionId);
  if (!c) return problem(`message for unknown subscription ${subscriptionId}`);
  let v;
  try {
    v = c.reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
  } catch (e) {
    return problem(`${c.topic}: message does not decode: ${e.message}`);
  }
  if (c.topic === "/diagnostics") {
    if (firstDiagnosticsStampMs === null) firstDiagnosticsStampMs = v.header.stamp.sec * 1000 + v.header.stamp.nanosec / 1e6;
    const names = v.status.map((s) => s.name);
    if (names.includes("uav1/sim0/pmu_1") && names.includes("uav1/sim0/bms_2")) good.add(c.topic);
  } else if (v.voltage > 1 && v.present === true && v.header.frame_id.startsWith("uav1/sim0/")) {
    good.add(c.topic);
  }
  if (good.size === Object.keys(want).length) finish();
});

let finished = false;
function finish() {
  if (finished) return;
  finished = true;
  for (const t of Object.keys(want)) if (!good.has(t)) problem(`no message of ${t} as checked`);
  if (when === "early" && firstAdvertised.some((t) => t in want))
    problem(`the first advertise already had ROS 2 channels (${firstAdvertised.join(", ")}): the client was not early`);
  if (when === "late") {
    for (const t of Object.keys(want)) if (!firstAdvertised.includes(t)) problem(`${t} not in the first advertise`);
    // The server's kept message, written before this client subscribed (same host, same clock),
    // not the next one the service writes.
    if (firstDiagnosticsStampMs === null || firstDiagnosticsStampMs >= diagnosticsSubscribedAt)
      problem(`the first /diagnostics message (stamp ${firstDiagnosticsStampMs} ms) is not the one kept from before the subscription (${diagnosticsSubscribedAt} ms)`);
  }
  client.close();
  if (problems.length) {
    console.error(problems.slice(0, 30).join("\n"));
    process.exit(1);
  }
  console.log(`serve_ros2_client ${when}: ${advertisements} advertisements, ${good.size} topics`);
  process.exit(0);
}
setTimeout(finish, Number(seconds) * 1000);
