// Compares what read_mcap.mjs decoded from `pmuctl decode --mcap` with `pmuctl decode --json`
// of the same log: every telemetry frame of the log is one message, in order, on the topic
// of its packet, at its candump time, with the same keys and values (floats as float32).
//   node compare_decode.mjs MCAP_LINES DECODE_JSON_LINES
import { readFileSync } from "node:fs";

const [mcapFile, jsonFile] = process.argv.slice(2);
const lines = (f) => readFileSync(f, "utf8").split("\n").filter((l) => l.trim()).map((l) => JSON.parse(l));
const messages = lines(mcapFile).filter((m) => !m.end);
const telemetry = new Set(["voltages", "currents", "battery_energy", "temperatures", "status"]);
const frames = lines(jsonFile).filter((j) => telemetry.has(j.packet) && !j.request && j.address !== undefined);

const problems = [];
if (messages.length !== frames.length)
  problems.push(`${messages.length} MCAP messages for ${frames.length} telemetry frames in the log`);
const same = (a, b) =>
  a === b ||
  (typeof a === "number" && typeof b === "number" && Math.abs(Math.fround(a) - Math.fround(b)) <= 1e-6 * Math.max(1, Math.abs(a)));
frames.forEach((f, i) => {
  const m = messages[i];
  if (!m) return;
  const where = `frame ${i} (${f.id} at ${f.time})`;
  if (m.topic !== `pmu/${f.packet}`) problems.push(`${where}: topic ${m.topic}, expected pmu/${f.packet}`);
  if (Math.abs(Number(m.log_time) / 1e9 - f.time) > 1e-6) problems.push(`${where}: log_time ${m.log_time}`);
  if (m.values.bus !== f.interface || m.values.address !== f.address || m.values.vehicle !== "")
    problems.push(`${where}: keys ${m.values.vehicle}/${m.values.bus}/${m.values.address}`);
  const keys = new Set(Object.keys(m.values).filter((k) => !["vehicle", "bus", "address"].includes(k)));
  for (const [k, v] of Object.entries(f.values)) {
    if (!keys.delete(k)) problems.push(`${where}: ${k} missing in the MCAP message`);
    else if (!same(v, m.values[k])) problems.push(`${where}: ${k} = ${JSON.stringify(m.values[k])}, pmuctl says ${v}`);
  }
  for (const k of keys) problems.push(`${where}: ${k} in the MCAP message but not in pmuctl's`);
});
if (problems.length) {
  console.error(problems.join("\n"));
  process.exit(1);
}
console.log(`compare_decode: ${frames.length} telemetry frames match`);
