// Checks what read_mcap.mjs printed for a recording of the simulated power system
// (deploy/examples/sim-power-system.yaml): messages on the PMU, battery and MPPT topics with
// the simulator's keys, values in plausible ranges, log times of this run.
//   node check_recording.mjs LINES [--crashed]
import { readFileSync } from "node:fs";

const [file, mode] = process.argv.slice(2);
const lines = readFileSync(file, "utf8").split("\n").filter((l) => l.trim()).map((l) => JSON.parse(l));
const end = lines.find((l) => l.end)?.end;
const messages = lines.filter((l) => !l.end);
const problems = [];
const by = (topic) => messages.filter((m) => m.topic === topic);
if (!end) problems.push("no end line");
if (mode === "--crashed") {
  if (end && end.footer) problems.push("a killed recorder left a footer?");
} else if (!end || !end.statistics || Number(end.statistics.message_count) !== messages.length) {
  problems.push(`summary: ${JSON.stringify(end)}`);
}
const now = Date.now() * 1e6;
for (const m of messages) {
  const t = Number(m.log_time);
  if (!(t > now - 600e9 && t < now + 10e9)) problems.push(`${m.topic}: log_time ${m.log_time} not of this run`);
  // Log time = max(publish time, the recording's start): state published before it.
  if (BigInt(m.publish_time) > BigInt(m.log_time)) problems.push(`${m.topic}: publish_time after log_time`);
}
const v = by("pmu/voltages");
if (v.length < 2) problems.push(`${v.length} pmu/voltages messages`);
for (const m of v) {
  if (m.values.bus !== "sim0" || m.values.address !== 1) problems.push(`voltages keys ${m.values.bus}/${m.values.address}`);
  if (!(m.values.avionics > 5 && m.values.avionics < 40)) problems.push(`voltages avionics ${m.values.avionics}`);
}
const seq = v.map((m) => m.sequence);
if (seq.some((s, i) => s !== i)) problems.push(`voltages sequences ${seq.slice(0, 10)}`);
const bat = by("pmu/battery").at(-1);
if (!bat) problems.push("no pmu/battery");
else if (bat.values.node !== 2 || !(bat.values.state_of_charge >= 0 && bat.values.state_of_charge <= 100))
  problems.push(`battery ${JSON.stringify(bat.values)}`);
if (!by("pmu/mppt").length) problems.push("no pmu/mppt");
if (!by("pmu/health").length) problems.push("no pmu/health");
if (problems.length) {
  console.error(problems.slice(0, 20).join("\n"));
  process.exit(1);
}
const topics = [...new Set(messages.map((m) => m.topic))].sort();
console.log(`check_recording: ${messages.length} messages on ${topics.join(", ")}`);
