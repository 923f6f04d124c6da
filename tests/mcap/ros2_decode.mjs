// Decodes the ROS 2 samples pmu-service wrote (captured as they came off the wire by
// tests/integration/ros2_dds_test.cpp: one JSON line each, {topic, type, cdr (hex), decoded})
// with Foxglove's own ROS 2 decoder (@foxglove/rosmsg2-serialization) and ROS 2 Jazzy's
// definitions as @foxglove/rosmsg-msgs-common carries them, and compares every field with what
// the generated C++ type read from the same bytes. Exit 1 naming the first difference.
//   node ros2_decode.mjs CAPTURE.jsonl [expected line count]
import { readFileSync } from "node:fs";
import { ros2jazzy } from "@foxglove/rosmsg-msgs-common";
import { MessageReader } from "@foxglove/rosmsg2-serialization";

const [file, wantLines] = process.argv.slice(2);
const lines = readFileSync(file, "utf8").split("\n").filter((l) => l.length > 0);
if (wantLines !== undefined && lines.length !== Number(wantLines)) {
  console.error(`FAIL: ${lines.length} captured samples, want ${wantLines}`);
  process.exit(1);
}

// "sensor_msgs/msg/BatteryState" -> the root definition first, then every other one (the
// reader finds the nested types by name among them).
function readerFor(type) {
  const name = type.replace("/msg/", "/");
  const root = ros2jazzy[name];
  if (!root) throw new Error(`no ROS 2 Jazzy definition of ${type}`);
  const others = Object.entries(ros2jazzy)
    .filter(([n]) => n !== name)
    .map(([n, d]) => ({ ...d, name: n }));
  return new MessageReader([root, ...others]);
}

// Float32 values travel as JSON numbers from the C++ float; NaN as null.
function same(actual, expected, path) {
  if (expected === null) {
    if (!(typeof actual === "number" && Number.isNaN(actual))) return `${path}: ${actual}, want NaN`;
    return null;
  }
  if (Array.isArray(expected)) {
    const a = Array.from(actual ?? []);
    if (a.length !== expected.length) return `${path}: ${a.length} elements, want ${expected.length}`;
    for (let i = 0; i < a.length; i++) {
      const d = same(a[i], expected[i], `${path}[${i}]`);
      if (d) return d;
    }
    return null;
  }
  if (typeof expected === "object") {
    for (const key of Object.keys(expected)) {
      if (!(key in (actual ?? {}))) return `${path}.${key}: absent in Foxglove's decode`;
      const d = same(actual[key], expected[key], `${path}.${key}`);
      if (d) return d;
    }
    return null;
  }
  if (typeof expected === "boolean") return actual === expected ? null : `${path}: ${actual}, want ${expected}`;
  if (typeof expected === "number")
    return Math.fround(Number(actual)) === Math.fround(expected) ? null : `${path}: ${actual}, want ${expected}`;
  return actual === expected ? null : `${path}: ${JSON.stringify(actual)}, want ${JSON.stringify(expected)}`;
}

for (const line of lines) {
  const sample = JSON.parse(line);
  const bytes = Uint8Array.from(Buffer.from(sample.cdr, "hex"));
  const reader = readerFor(sample.type);
  const decoded = reader.readMessage(bytes);
  // What the decode left over may only be zero padding to the payload's 4-byte boundary:
  // Fast DDS 2.9 pads the DATA submessage so without counting it in the encapsulation
  // options, and CDR readers (ROS 2's among them) skip it. More is a layout mismatch.
  const used = reader.lastReadByteLength();
  const left = bytes.subarray(used);
  if (left.length > 3 || (used + left.length) % 4 !== 0 || left.some((b) => b !== 0)) {
    console.error(`FAIL: ${sample.topic}: ${left.length} bytes left after ${sample.type} (${Buffer.from(left).toString("hex")})`);
    process.exit(1);
  }
  const difference = same(decoded, sample.decoded, sample.topic);
  if (difference) {
    console.error(`FAIL: ${difference}`);
    process.exit(1);
  }
  console.log(`${sample.topic} ${sample.type}: ${bytes.length} bytes, every field as the service wrote it`);
  console.log(JSON.stringify(decoded, (k, v) => (ArrayBuffer.isView(v) ? Array.from(v) : Number.isNaN(v) ? "NaN" : v)));
}
