// Drives headless Chromium (puppeteer-core) to the test page and judges what the page saw of
// `pmuctl serve` (docs/interface.md section 9.2) against pmu-service on the simulated power
// system (deploy/examples/sim-power-system.yaml).
//   node drive.mjs CHROMIUM PAGE-URL WS-URL SUBPROTOCOL VOLTAGES SCREENSHOT.png [--refused]
// The page reads until it has VOLTAGES pmu/voltages messages (page.mjs).
// The page's plot is saved to SCREENSHOT.png whatever the verdict. With --refused the page's
// origin is one the server must refuse: the page must get no connection and nothing from it.
// Host names ending in .test are this host (Chromium's resolver is told so), so a page can
// have an origin other than a local one. Exit status 0 when every check passed; 1 with the
// problems on stderr.
import puppeteer from "puppeteer-core";

const [chromium, pageUrl, wsUrl, subprotocol, voltages, screenshot, expect] = process.argv.slice(2);
const refused = expect === "--refused";
const problems = [];
const problem = (p) => problems.push(p);

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  // The https page and wss:// use a certificate made for this run; root has no sandbox.
  args: [
    "--ignore-certificate-errors",
    "--host-resolver-rules=MAP *.test 127.0.0.1",
    ...(process.getuid?.() === 0 ? ["--no-sandbox"] : []),
  ],
});
let result;
try {
  const page = await browser.newPage();
  const consoleLines = [];
  page.on("console", (m) => consoleLines.push(`${m.type()}: ${m.text()}`));
  page.on("pageerror", (e) => problem(`page error: ${e.message}`));
  const query = new URLSearchParams({ ws: wsUrl, protocol: subprotocol, voltages });
  await page.goto(`${pageUrl}/index.html?${query}`);
  // The page hands its result over once it has what it waits for (DDS discovery first);
  // the bound only turns "never" into a FAIL.
  await page.waitForFunction(() => window.pmuResult !== undefined, { timeout: 60000 });
  result = await page.evaluate(() => window.pmuResult);
  const canvas = await page.$("#plot");
  await canvas.screenshot({ path: screenshot });
  console.log(`screenshot: ${screenshot}`);
  // A refused WebSocket is an error on the console; anything else there is a problem.
  if (!refused && consoleLines.some((l) => l.startsWith("error"))) problem(`console: ${consoleLines.join("; ")}`);
} finally {
  await browser.close();
}

const origin = new URL(pageUrl).origin;
if (result.origin !== origin) problem(`page origin ${result.origin}, not ${origin}`);
if (refused) {
  // The handshake fails: no subprotocol, no serverInfo, no message, an abnormal close.
  if (result.negotiated !== "" || result.serverInfo || result.times.length || result.messages["pmu/voltages"].length)
    problem(`a page from ${origin} was served: ${JSON.stringify({ negotiated: result.negotiated, serverInfo: result.serverInfo })}`);
  if (result.closeCode !== 1006) problem(`a page from ${origin}: close code ${result.closeCode}, not 1006 (handshake refused)`);
  if (problems.length) {
    console.error(problems.join("\n"));
    process.exit(1);
  }
  console.log(`browser ${origin} -> ${result.url}: refused (${result.errors.join("; ")})`);
  process.exit(0);
}
for (const e of result.errors) problem(`page: ${e}`);
if (result.negotiated !== subprotocol) problem(`offered ${subprotocol}, negotiated "${result.negotiated}"`);

// serverInfo: pmuctl's, with the `time` capability.
const info = result.serverInfo;
if (!info) problem("no serverInfo");
else {
  if (!/pmuctl/.test(info.name)) problem(`serverInfo name ${info.name}`);
  if (!info.capabilities?.includes("time")) problem(`serverInfo capabilities ${JSON.stringify(info.capabilities)} lack "time"`);
}
for (const [topic, c] of Object.entries(result.advertised).filter(([t]) => t === "pmu/voltages" || t === "pmu/battery"))
  if (c.encoding !== "cdr" || c.schemaEncoding !== "omgidl") problem(`${topic}: ${c.encoding}/${c.schemaEncoding}`);
if (!result.advertised["pmu/voltages"] || !result.advertised["pmu/battery"]) problem(`advertised ${Object.keys(result.advertised)}`);

// Time messages: several, never going back.
const times = result.times.map((t) => BigInt(t.time_ns));
if (times.length < 2) problem(`${times.length} Time messages (opcode 0x02)`);
for (let i = 1; i < times.length; i++) if (times[i] < times[i - 1]) problem(`Time went back: ${times[i - 1]} then ${times[i]}`);

// Messages: live values with the simulator's keys; each timestamp is the CAN receive time, the
// server's clock as its Time messages give it: within a few seconds of the last Time before it.
const volts = result.messages["pmu/voltages"];
const battery = result.messages["pmu/battery"];
if (volts.length < Number(voltages)) problem(`${volts.length} pmu/voltages messages`);
if (battery.length < 2) problem(`${battery.length} pmu/battery messages`);
for (const m of volts) {
  const v = m.values;
  if (v.bus !== "sim0" || v.address !== 1 || typeof v.vehicle !== "string") problem(`voltages keys ${v.vehicle}/${v.bus}/${v.address}`);
  for (const f of ["avionics", "output_28v", "payload", "battery_a"])
    if (!(v[f] > 3 && v[f] < 40)) problem(`voltages ${f} ${v[f]} V is not a plausible voltage`);
}
for (const m of battery) {
  const v = m.values;
  if (v.bus !== "sim0" || v.node !== 2) problem(`battery keys ${v.bus}/${v.node}`);
  if (!(v.voltage > 10 && v.voltage < 60)) problem(`battery voltage ${v.voltage} V`);
  if (!(v.state_of_charge >= 0 && v.state_of_charge <= 100)) problem(`battery state_of_charge ${v.state_of_charge}`);
}
const withinSeconds = 3n * 1000000000n;
for (const [topic, list] of Object.entries(result.messages))
  for (const m of list) {
    if (m.latest_time_ns === null) {
      problem(`${topic}: a message came before any Time message`);
      break;
    }
    const d = BigInt(m.timestamp_ns) - BigInt(m.latest_time_ns);
    if (d > withinSeconds || d < -withinSeconds) problem(`${topic}: timestamp ${m.timestamp_ns} is ${Number(d) / 1e9} s from the last Time ${m.latest_time_ns}`);
  }
for (let i = 1; i < volts.length; i++)
  if (BigInt(volts[i].timestamp_ns) <= BigInt(volts[i - 1].timestamp_ns)) problem(`voltages timestamps not increasing at ${i}`);

// The plot: every sample on the message-timestamp axis, both axes labelled.
const plot = result.plot;
if (plot.points !== volts.length) problem(`plot has ${plot.points} points for ${volts.length} samples`);
if (!plot.timeAxis || !/message timestamp/.test(plot.xLabel)) problem(`plot x axis: ${plot.xLabel}`);
if (!/avionics \(V\)/.test(plot.yLabel)) problem(`plot y axis: ${plot.yLabel}`);

if (problems.length) {
  console.error(problems.slice(0, 30).join("\n"));
  process.exit(1);
}
const span = volts.length ? (Number(BigInt(volts.at(-1).timestamp_ns) - BigInt(volts[0].timestamp_ns)) / 1e9).toFixed(1) : 0;
console.log(
  `browser ${result.origin} -> ${result.url} (${result.negotiated}): ${volts.length} voltages over ${span} s ` +
    `(avionics ${volts.at(-1).values.avionics.toFixed(2)} V), ${battery.length} battery ` +
    `(${battery.at(-1).values.voltage.toFixed(2)} V, ${battery.at(-1).values.state_of_charge.toFixed(0)} %), ${times.length} Time messages`,
);
