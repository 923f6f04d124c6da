// A ground station made of node-mavlink (npm, tests/mavlink's package) that signs, for
// signing_end_to_end.sh:
//   node signed_ground_station.mjs PORTFILE OUTFILE PASSPHRASE commands|learn
// Listens on a UDP port of 127.0.0.1 (written to PORTFILE once bound). Its key is SHA-256 of
// PASSPHRASE, node-mavlink's MavLinkPacketSignature.key, as Mission Planner and MAVProxy
// derive theirs. Every frame pmu-mavlink sends is checked under node-mavlink: signed, the
// signature matching the key, link id 0, timestamps increasing and within a minute of this
// clock; a frame that is not is one "problem" line in OUTFILE, and each frame one JSON line.
//
// commands: at the first HEARTBEAT, a signed SET_MESSAGE_INTERVAL (GENERATOR_STATUS at 4 Hz);
// at its COMMAND_ACK, three frames that must go unanswered, an unsigned RUN_PREARM_CHECKS,
// a SET_MESSAGE_INTERVAL signed with another key and the first SET_MESSAGE_INTERVAL's bytes
// again (a replay), then a signed MAV_CMD_USER_1 (31000). pmu-mavlink takes frames in the
// order they come, so once that last one is answered (UNSUPPORTED) the three before it have
// been judged: exit 0 then. signing_end_to_end.sh reads the answers from OUTFILE.
// learn: plays the autopilot for a pmu-mavlink without --system-id: at the first frame, an
// unsigned ArduPilot HEARTBEAT from system 9, then a signed one from system 7; exit 0 at the
// first frame from system 7, exit 1 at one from system 9 (the unsigned one was believed).
import { createSocket } from 'node:dgram'
import { writeFileSync, appendFileSync } from 'node:fs'
import { PassThrough } from 'node:stream'
import { createMavLinkStream, MavLinkProtocolV2, MavLinkPacketSignature, minimal, common } from 'node-mavlink'

const REGISTRY = { ...minimal.REGISTRY, ...common.REGISTRY }
const [portFile, outFile, passphrase, mode] = process.argv.slice(2)
const key = MavLinkPacketSignature.key(passphrase)
const otherKey = MavLinkPacketSignature.key(passphrase + ' but another')
writeFileSync(outFile, '')
const socket = createSocket('udp4')
const bytes = new PassThrough()
let peer = null
socket.on('message', (msg, rinfo) => { peer = rinfo; bytes.write(msg) })
socket.bind(0, '127.0.0.1', () => writeFileSync(portFile, String(socket.address().port)))

let seq = 0
// Milliseconds for node-mavlink's sign(): at least one more per frame, so each frame of the
// stream is newer than the one before.
let lastMs = 0
function stampMs() { lastMs = Math.max(Date.now(), lastMs + 1); return lastMs }
function frame(sysid, compid, clazz, values, signWith) {
  const protocol = new MavLinkProtocolV2(sysid, compid, signWith ? MavLinkProtocolV2.IFLAG_SIGNED : 0)
  const buffer = protocol.serialize(Object.assign(new clazz(), values), seq++)
  return signWith ? protocol.sign(buffer, 1, signWith, stampMs()) : buffer
}
const put = (buffer) => socket.send(buffer, peer.port, peer.address)
const record = (o) => appendFileSync(outFile, JSON.stringify(o) + '\n')
function command(target, command, params, signWith) {
  const p = {}
  for (let i = 0; i < 7; i++) p[`_param${i + 1}`] = params[i] ?? 0
  return frame(255, 190, common.CommandLong, { targetSystem: target.sysid, targetComponent: target.compid, command,
    confirmation: 0, ...p }, signWith)
}

let lastStamp = -1
let firstRequest = null
let askedBad = false
for await (const packet of createMavLinkStream(bytes)) {
  const h = packet.header
  const clazz = REGISTRY[h.msgid]
  if (!clazz) continue
  const data = packet.protocol.data(packet.payload, clazz)
  const sig = packet.signature
  const nowStamp = (Date.now() - MavLinkProtocolV2.SIGNATURE_START_TIME) * 100
  const line = { name: clazz.MSG_NAME, sysid: h.sysid, compid: h.compid, signed: !!sig }
  if (h.msgid === common.CommandAck.MSG_ID) line.ack = { command: data.command, result: data.result }
  record(line)
  if (!sig) record({ problem: `${clazz.MSG_NAME} not signed` })
  else {
    if (!sig.matches(key)) record({ problem: `${clazz.MSG_NAME}: the signature does not match the key` })
    if (sig.linkId !== 0) record({ problem: `${clazz.MSG_NAME}: link id ${sig.linkId}, want 0` })
    if (sig.timestamp <= lastStamp) record({ problem: `${clazz.MSG_NAME}: timestamp ${sig.timestamp} not after ${lastStamp}` })
    if (Math.abs(sig.timestamp - nowStamp) > 6000000) record({ problem: `${clazz.MSG_NAME}: timestamp ${sig.timestamp}, this clock ${nowStamp}` })
    lastStamp = sig.timestamp
  }
  const target = { sysid: h.sysid, compid: h.compid }
  if (mode === 'learn') {
    if (h.sysid === 7 && h.compid === 180) { socket.close(); process.exit(0) }
    if (h.sysid === 9) { record({ problem: 'took system 9 from an unsigned HEARTBEAT' }); socket.close(); process.exit(1) }
    if (lastMs === 0) {
      // ArduPilot's HEARTBEAT: MAV_TYPE_FIXED_WING (1), MAV_AUTOPILOT_ARDUPILOTMEGA (3).
      const hb = { type: 1, autopilot: 3, baseMode: 0, customMode: 0, systemStatus: 3, mavlinkVersion: 3 }
      put(frame(9, 1, minimal.Heartbeat, hb, null))
      put(frame(7, 1, minimal.Heartbeat, hb, key))
    }
    continue
  }
  if (h.msgid === minimal.Heartbeat.MSG_ID && !firstRequest) {
    firstRequest = command(target, 511, [373, 250000], key)
    put(firstRequest)
  }
  if (line.ack?.command === 511 && !askedBad) {
    askedBad = true
    put(command(target, 401, [], null))
    put(command(target, 511, [373, 500000], otherKey))
    put(firstRequest)
    put(command(target, 31000, [], key))
  }
  if (line.ack?.command === 31000) { socket.close(); process.exit(0) }
}
