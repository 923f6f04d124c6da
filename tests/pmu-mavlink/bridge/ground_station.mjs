// A ground station made of node-mavlink (npm, tests/mavlink's package) for end_to_end.sh:
//   node ground_station.mjs PORTFILE OUTFILE [learn|unknown]
// Listens on a UDP port of 127.0.0.1 (written to PORTFILE once bound), decodes every frame
// pmu-mavlink sends there (directly, or through pty_relay.py from a serial line) and writes
// it as one JSON line to OUTFILE. Once it has the messages end_to_end.sh checks (HEARTBEAT,
// BATTERY_STATUS 10, 11 and 20 and GENERATOR_STATUS with values, RELAY_STATUS with PMU 0's
// outputs present), it answers from where the frames came (as a GCS on mavlink-router's UDP
// endpoint would): noise and a frame with a bad CRC, then SET_MESSAGE_INTERVAL for
// GENERATOR_STATUS and RUN_PREARM_CHECKS, and waits
// for both COMMAND_ACKs and the pre-arm STATUSTEXT lines. Exit 0 then; end_to_end.sh bounds
// the wait. With `learn` it plays the autopilot instead: on the first frame it sends an
// ArduPilot HEARTBEAT from system 7, component 1, and exits 0 at the first frame from
// system 7, component 180 (pmu-mavlink took the autopilot's system id). With `unknown` it
// exits 0 at the first RELAY_STATUS after a GENERATOR_STATUS saying COMMUNICATION_WARNING
// (a PMU pmu-mavlink knows of, not ONLINE).
import { createSocket } from 'node:dgram'
import { writeFileSync, appendFileSync } from 'node:fs'
import { PassThrough } from 'node:stream'
import { createMavLinkStream, MavLinkProtocolV2, MSG_ID_MAGIC_NUMBER, minimal, common } from 'node-mavlink'

const REGISTRY = { ...minimal.REGISTRY, ...common.REGISTRY }
const [portFile, outFile, mode] = process.argv.slice(2)
writeFileSync(outFile, '')
const socket = createSocket('udp4')
const bytes = new PassThrough()
let peer = null
socket.on('message', (msg, rinfo) => { peer = rinfo; bytes.write(msg) })
socket.bind(0, '127.0.0.1', () => writeFileSync(portFile, String(socket.address().port)))

const gcs = new MavLinkProtocolV2(255, 190)
let seq = 0
function send(clazz, values) {
  const buffer = gcs.serialize(Object.assign(new clazz(), values), seq++)
  socket.send(buffer, peer.port, peer.address)
}

const have = new Set()
let asked = false
const acks = new Map()
let prearmLines = 0
const plain = (v) => typeof v === 'bigint' ? v.toString() : (typeof v === 'number' && Number.isNaN(v)) ? 'NaN' : v
// RELAY_STATUS (376) is not in node-mavlink 2.3.0's definitions: its CRC_EXTRA (199, from
// common.xml by mavgen's rule, /work/shared/research/mavlink.md) lets the splitter check the
// frame's CRC, and its three fields are read here (a truncated payload's tail is zeros).
const RELAY_STATUS = 376
const magicNumbers = { ...MSG_ID_MAGIC_NUMBER, [RELAY_STATUS]: 199 }
function relayStatus(payload) {
  const p = Buffer.concat([payload, Buffer.alloc(8)])
  return { timeBootMs: p.readUInt32LE(0), on: p.readUInt16LE(4), present: p.readUInt16LE(6) }
}
let sawNotOnline = false
for await (const packet of createMavLinkStream(bytes, { magicNumbers })) {
  const h = packet.header
  const clazz = REGISTRY[h.msgid]
  if (!clazz && h.msgid !== RELAY_STATUS) continue
  let data = {}
  const fields = {}
  if (clazz) {
    data = packet.protocol.data(packet.payload, clazz)
    for (const f of clazz.FIELDS) fields[f.name] = Array.isArray(data[f.name]) ? data[f.name].map(plain) : plain(data[f.name])
  } else {
    Object.assign(fields, relayStatus(packet.payload))
  }
  const name = clazz ? clazz.MSG_NAME : 'RELAY_STATUS'
  appendFileSync(outFile, JSON.stringify({ msgid: h.msgid, name, sysid: h.sysid, compid: h.compid, fields }) + '\n')
  if (mode === 'unknown') {
    // MAV_GENERATOR_STATUS_FLAG_COMMUNICATION_WARNING (4096) alone: the PMU is not ONLINE.
    if (h.msgid === common.GeneratorStatus.MSG_ID && BigInt(data.status) === 4096n) sawNotOnline = true
    if (h.msgid === RELAY_STATUS && sawNotOnline) { socket.close(); process.exit(0) }
    continue
  }
  if (mode === 'learn') {
    if (h.sysid === 7 && h.compid === 180) { socket.close(); process.exit(0) }
    // ArduPilot's HEARTBEAT: MAV_TYPE_FIXED_WING (1), MAV_AUTOPILOT_ARDUPILOTMEGA (3).
    const autopilot = new MavLinkProtocolV2(7, 1)
    const hb = Object.assign(new minimal.Heartbeat(), { type: 1, autopilot: 3, baseMode: 0, customMode: 0, systemStatus: 3, mavlinkVersion: 3 })
    socket.send(autopilot.serialize(hb, seq++), peer.port, peer.address)
    continue
  }
  if (h.msgid === minimal.Heartbeat.MSG_ID) have.add('heartbeat')
  if (h.msgid === common.BatteryStatus.MSG_ID && data.voltages[0] !== 65535) have.add(`battery ${data.id}`)
  if (h.msgid === common.GeneratorStatus.MSG_ID && !Number.isNaN(data.busVoltage)) have.add('generator')
  if (h.msgid === RELAY_STATUS && (fields.present & 0x1f) === 0x1f) have.add('relay')
  if (h.msgid === common.CommandAck.MSG_ID) acks.set(data.command, data.result)
  if (h.msgid === common.StatusText.MSG_ID && /^PreArm: |^PMU: pre-arm/.test(data.text)) prearmLines++
  const ready = ['heartbeat', 'battery 10', 'battery 11', 'battery 20', 'generator', 'relay'].every((k) => have.has(k))
  if (ready && !asked) {
    asked = true
    // Bad input first: noise, and a HEARTBEAT whose CRC is wrong. pmu-mavlink counts both
    // and goes on (end_to_end.sh reads its counts).
    socket.send(Buffer.from(Array.from({ length: 64 }, (_, i) => (i * 37 + 11) & 0x7f)), peer.port, peer.address)
    const bad = gcs.serialize(Object.assign(new minimal.Heartbeat(), { type: 6, autopilot: 8, baseMode: 0, customMode: 0, systemStatus: 4, mavlinkVersion: 3 }), seq++)
    bad[bad.length - 1] ^= 0xff
    socket.send(bad, peer.port, peer.address)
    // GENERATOR_STATUS at 4 Hz; then the pre-arm checks of the component.
    send(common.CommandLong, { targetSystem: h.sysid, targetComponent: h.compid, command: 511, confirmation: 0,
      _param1: 373, _param2: 250000, _param3: 0, _param4: 0, _param5: 0, _param6: 0, _param7: 0 })
    send(common.CommandLong, { targetSystem: h.sysid, targetComponent: h.compid, command: 401, confirmation: 0,
      _param1: 0, _param2: 0, _param3: 0, _param4: 0, _param5: 0, _param6: 0, _param7: 0 })
  }
  if (asked && acks.has(511) && acks.has(401) && prearmLines > 0) {
    socket.close()
    process.exit(0)
  }
}
