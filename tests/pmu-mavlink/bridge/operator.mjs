// A ground station's operator made of node-mavlink (npm, tests/mavlink's package) for
// operate_end_to_end.sh:
//   node operator.mjs PORTFILE OUTFILE MODE
// Listens on a UDP port of 127.0.0.1 (written to PORTFILE once bound), takes pmu-mavlink's
// first HEARTBEAT as the component to talk to, and writes every message it receives, and
// every one it sends ({"sent": NAME, ...}), as one JSON line to OUTFILE. Steps go one after
// the other, each on the answer to the one before; exit 0 after the last, and
// operate_end_to_end.sh bounds the wait and checks OUTFILE.
//   operate: the parameter list as a ground station gets it (PARAM_REQUEST_LIST to every
//            component, what is missing asked again by index every 3 s), a set of
//            PMU1_SERVO_V addressed to the autopilot (component 1), then to pmu-mavlink
//            to another value, a set of it out of range, DO_SET_RELAY payload
//            off, DO_ENGINE_CONTROL start (DENIED without --confirm engine_start).
//   start:   once PMU1 is known (a read of PMU1_SERVO_V answered), DO_ENGINE_CONTROL start,
//            the same COMMAND_LONG again with confirmation 1 at its first IN_PROGRESS (a
//            ground station's retransmission), until the final COMMAND_ACK.
import { createSocket } from 'node:dgram'
import { writeFileSync, appendFileSync } from 'node:fs'
import { PassThrough } from 'node:stream'
import { createMavLinkStream, MavLinkProtocolV2, minimal, common } from 'node-mavlink'

const REGISTRY = { ...minimal.REGISTRY, ...common.REGISTRY }
const [portFile, outFile, mode] = process.argv.slice(2)
writeFileSync(outFile, '')
const socket = createSocket('udp4')
const bytes = new PassThrough()
let peer = null
socket.on('message', (msg, rinfo) => { peer = rinfo; bytes.write(msg) })
socket.bind(0, '127.0.0.1', () => writeFileSync(portFile, String(socket.address().port)))

const plain = (v) => typeof v === 'bigint' ? v.toString() : (typeof v === 'number' && Number.isNaN(v)) ? 'NaN' : v
const record = (entry) => appendFileSync(outFile, JSON.stringify(entry) + '\n')

const gcs = new MavLinkProtocolV2(255, 190)
let seq = 0
function send(clazz, values) {
  const message = Object.assign(new clazz(), values)
  socket.send(gcs.serialize(message, seq++), peer.port, peer.address)
  const fields = {}
  for (const f of clazz.FIELDS) fields[f.name] = plain(message[f.name])
  record({ sent: clazz.MSG_NAME, fields })
}

let target = null  // [system, component] of pmu-mavlink
const command = (id, params, confirmation = 0) => {
  const p = [0, 0, 0, 0, 0, 0, 0]
  params.forEach((v, i) => { p[i] = v })
  send(common.CommandLong, { targetSystem: target[0], targetComponent: target[1], command: id, confirmation,
    _param1: p[0], _param2: p[1], _param3: p[2], _param4: p[3], _param5: p[4], _param6: p[5], _param7: p[6] })
}
const paramSet = (name, value) => send(common.ParamSet, { targetSystem: target[0], targetComponent: target[1],
  paramId: name, paramValue: value, paramType: 9 })
const paramRead = (name, index) => send(common.ParamRequestRead, { targetSystem: target[0], targetComponent: target[1],
  paramId: name, paramIndex: index })
const done = () => { socket.close(); process.exit(0) }
const after = (ms, f) => setTimeout(f, ms)

// The operate steps, each started by what answered the one before.
const values = new Map()  // param_index -> { name, value }
let paramCount = null
let step = 'list'
let servo = null  // the value set
let listTimer = null
function askList() {
  if (step !== 'list') return
  if (paramCount === null) {
    // QGroundControl's way: every component of the system.
    send(common.ParamRequestList, { targetSystem: target[0], targetComponent: 0 })
  } else {
    for (let i = 0; i < paramCount; i++) if (!values.has(i)) paramRead('', i)
  }
  listTimer = after(3000, askList)
}
function servoName() { return 'PMU1_SERVO_V' }

function operate(name, data) {
  if (name === 'PARAM_VALUE') {
    paramCount = data.paramCount
    if (step === 'list') {
      values.set(data.paramIndex, { name: data.paramId, value: data.paramValue })
      if (values.size === paramCount) {
        clearTimeout(listTimer)
        step = 'set'
        const now = [...values.values()].find((v) => v.name === servoName()).value
        servo = Math.abs(now - 7.5) < 0.01 ? 8.0 : 7.5
        // The autopilot's: not pmu-mavlink's to answer or carry out.
        send(common.ParamSet, { targetSystem: target[0], targetComponent: 1, paramId: servoName(), paramValue: 9.0, paramType: 9 })
        paramSet(servoName(), servo)
      }
    } else if (step === 'set' && data.paramId === servoName()) {
      // Exactly one PARAM_VALUE answers the set: 2 s more show that no second one comes.
      step = 'set-quiet'
      after(2000, () => { step = 'refuse'; paramSet(servoName(), 30.0) })
    } else if (step === 'refuse' && data.paramId === servoName()) {
      step = 'refuse-text'
    }
  } else if (name === 'STATUSTEXT' && step === 'refuse-text' && data.text.startsWith(`${servoName()} not set`)) {
    step = 'relay'
    command(181, [1, 0])  // DO_SET_RELAY instance 1 (payload) off
  } else if (name === 'COMMAND_ACK' && step === 'relay' && data.command === 181 && data.result !== 5) {
    step = 'start-denied'
    command(223, [1])  // DO_ENGINE_CONTROL start
  } else if (name === 'COMMAND_ACK' && step === 'start-denied' && data.command === 223 && data.result !== 5) {
    step = 'start-denied-text'
    after(1000, done)  // its STATUSTEXT follows the ack in the same turn
  }
}

let startStep = 'known'
let knownTimer = null
function askKnown() {
  if (startStep !== 'known') return
  paramRead(servoName(), -1)
  knownTimer = after(1000, askKnown)
}
function start(name, data) {
  if (name === 'PARAM_VALUE' && startStep === 'known' && data.paramId === servoName()) {
    clearTimeout(knownTimer)
    startStep = 'started'
    command(223, [1])
  } else if (name === 'COMMAND_ACK' && data.command === 223) {
    if (data.result === 5 && startStep === 'started') {
      startStep = 'retransmitted'
      command(223, [1], 1)
    } else if (data.result !== 5) {
      after(500, done)
    }
  }
}

for await (const packet of createMavLinkStream(bytes)) {
  const h = packet.header
  const clazz = REGISTRY[h.msgid]
  if (!clazz) continue
  const data = packet.protocol.data(packet.payload, clazz)
  const fields = {}
  for (const f of clazz.FIELDS) fields[f.name] = Array.isArray(data[f.name]) ? data[f.name].map(plain) : plain(data[f.name])
  record({ msgid: h.msgid, name: clazz.MSG_NAME, sysid: h.sysid, compid: h.compid, fields })
  if (!target) {
    if (h.msgid !== minimal.Heartbeat.MSG_ID) continue
    target = [h.sysid, h.compid]
    if (mode === 'operate') askList()
    else askKnown()
    continue
  }
  if (mode === 'operate') operate(clazz.MSG_NAME, data)
  else start(clazz.MSG_NAME, data)
}
