// Checks the ROS 2 channels of a recording read by read_mcap.mjs (one JSON line per message,
// then {"end": ...}): pmu-service with `vehicle: uav1` and `ros2: {enabled: true}` on the
// simulated power system (bus sim0: PMU 1 with batteries on both inputs, BMS node 2). Each
// message was decoded by Foxglove's ROS 2 decoder from the channel's ros2msg schema.
//   node check_ros2_recording.mjs FILE.jsonl [--batteries | --no-batteries] [--only-ros2] [--crashed]
// --batteries: the three battery channels are there with their messages; --no-batteries: no
// battery channel; --only-ros2: no contract channel. --crashed: a stream read (no summary).
// Exit 1 naming the first thing wrong.
import { readFileSync } from "node:fs";

const [file, ...flags] = process.argv.slice(2);
const lines = readFileSync(file, "utf8").split("\n").filter((l) => l.length > 0).map((l) => JSON.parse(l));
const end = lines.find((l) => l.end)?.end;
const messages = lines.filter((l) => !l.end);
const fail = (why) => {
  console.error(`FAIL: ${why}`);
  process.exit(1);
};
if (!end) fail("no end line: the reader stopped");

const batteries = ["/uav1/sim0/pmu_1/battery_a", "/uav1/sim0/pmu_1/battery_b", "/uav1/sim0/bms_2/battery"];
const of = (topic) => messages.filter((m) => m.topic === topic);
const topics = new Set(flags.includes("--crashed") ? messages.map((m) => m.topic) : end.topics);

// /diagnostics: Foxglove's Diagnostics panel reads diagnostic_msgs/msg/DiagnosticArray there.
const diagnostics = of("/diagnostics");
if (diagnostics.length === 0) fail(`no /diagnostics message (topics: ${[...topics].join(", ")})`);
for (const m of diagnostics)
  if (m.schema !== "diagnostic_msgs/msg/DiagnosticArray") fail(`/diagnostics schema ${m.schema}`);
// Every message holds every device's status: the last one names the PMU and the BMS.
const last = diagnostics[diagnostics.length - 1].values;
const names = last.status.map((s) => s.name);
for (const want of ["uav1/sim0/pmu_1", "uav1/sim0/bms_2"])
  if (!names.includes(want)) fail(`the last /diagnostics message has no status ${want}: ${names.join(", ")}`);
const pmu = last.status.find((s) => s.name === "uav1/sim0/pmu_1");
if (!pmu.values.some((kv) => kv.key === "frames_received")) fail("the PMU's status has no frames_received");
if (typeof last.header.stamp.sec !== "number" || last.header.stamp.sec < 1.6e9) fail(`header.stamp ${JSON.stringify(last.header.stamp)}`);

if (flags.includes("--batteries")) {
  for (const topic of batteries) {
    const ms = of(topic);
    if (ms.length === 0) fail(`no ${topic} message (topics: ${[...topics].join(", ")})`);
    for (const m of ms) if (m.schema !== "sensor_msgs/msg/BatteryState") fail(`${topic} schema ${m.schema}`);
    const v = ms[ms.length - 1].values;
    if (!(v.voltage > 1)) fail(`${topic}: voltage ${v.voltage}`);
    if (v.present !== true) fail(`${topic}: present ${v.present}`);
    if (!v.header.frame_id.startsWith("uav1/sim0/")) fail(`${topic}: frame_id ${v.header.frame_id}`);
  }
}
if (flags.includes("--no-batteries"))
  for (const topic of topics) if (topic.startsWith("/") && topic !== "/diagnostics") fail(`a ROS 2 battery channel ${topic}`);
if (flags.includes("--only-ros2"))
  for (const topic of topics) if (!topic.startsWith("/")) fail(`a contract channel ${topic}`);
if (!flags.includes("--crashed") && end.schemas) {
  for (const s of end.schemas)
    if (s.name.includes("/msg/") !== (s.encoding === "ros2msg")) fail(`schema ${s.name} encoded ${s.encoding}`);
}
console.log(`ok: ${messages.length} messages, ${diagnostics.length} on /diagnostics, topics ${[...topics].join(", ")}`);
