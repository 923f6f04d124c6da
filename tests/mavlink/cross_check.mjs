// node-mavlink's side of the cross-check (cross_check.sh):
//   node cross_check.mjs decode KEYHEX FILE   pmu::mavlink's frames (mavlink_cross_frames
//                                             write): split, CRC-checked, decoded and compared
//   node cross_check.mjs encode KEYHEX        frames node-mavlink serializes (unsigned and
//                                             signed), one JSON line each, on stdout
// The line format is cross_frames.cpp's. Exit status 1 with each difference on stderr.
import { readFileSync } from 'node:fs'
import { Readable } from 'node:stream'
import { createMavLinkStream, MavLinkProtocolV2, minimal, common } from 'node-mavlink'

const REGISTRY = { ...minimal.REGISTRY, ...common.REGISTRY }
const [mode, keyHex, file] = process.argv.slice(2)
const key = Buffer.from(keyHex ?? '', 'hex')
if (key.length !== 32 || !['decode', 'encode'].includes(mode)) {
  console.error('usage: cross_check.mjs decode KEYHEX FILE | encode KEYHEX')
  process.exit(2)
}

const isArray = (field) => field.length > 0 && field.type !== 'char[]'

// A decoded value against the record's: NaN is "NaN", uint64 a decimal string.
function same(field, actual, expected) {
  if (isArray(field)) {
    return Array.isArray(expected) && expected.length === actual.length &&
      actual.every((v, i) => v === expected[i])
  }
  if (field.type === 'uint64_t') return actual === BigInt(expected)
  if (expected === 'NaN') return Number.isNaN(actual)
  return actual === expected
}

async function decode() {
  const all = readFileSync(file, 'utf8').split('\n').filter((l) => l).map((l) => JSON.parse(l))
  const bytes = Buffer.concat(all.map((r) => Buffer.from(r.hex, 'hex')))
  // A message node-mavlink's definitions lack (RELAY_STATUS in node-mavlink 2.3.0) has no
  // CRC_EXTRA there: its splitter skips the frame, so it cannot be checked here, and says so.
  const records = all.filter((r) => REGISTRY[r.msgid])
  const unchecked = [...new Set(all.filter((r) => !REGISTRY[r.msgid]).map((r) => r.msgid))]
  for (const id of unchecked) console.log(`message ${id}: not in node-mavlink's definitions, not cross-checked`)
  if (records.length < all.length / 2) console.error('most frames not cross-checked'), process.exit(1)
  // Chunks of 7 bytes: node-mavlink's splitter reassembles frames across them.
  const chunks = []
  for (let i = 0; i < bytes.length; i += 7) chunks.push(bytes.subarray(i, i + 7))
  const crcErrors = []
  const packets = []
  const stream = createMavLinkStream(Readable.from(chunks), { onCrcError: (b) => crcErrors.push(b) })
  for await (const packet of stream) packets.push(packet)

  let differences = 0
  const differ = (i, what) => { console.error(`record ${i + 1} (msgid ${records[i]?.msgid}): ${what}`); differences++ }
  if (crcErrors.length) console.error(`node-mavlink: ${crcErrors.length} CRC errors`), differences++
  if (packets.length !== records.length) {
    console.error(`node-mavlink split ${packets.length} packets from ${records.length} frames`)
    process.exit(1)
  }
  packets.forEach((packet, i) => {
    const rec = records[i]
    const h = packet.header
    for (const [name, actual, expected] of [
      ['msgid', h.msgid, rec.msgid], ['sysid', h.sysid, rec.sysid], ['compid', h.compid, rec.compid],
      ['seq', h.seq, rec.seq], ['payload length', h.payloadLength, rec.payload_length], ['crc', packet.crc, rec.crc],
    ]) if (actual !== expected) differ(i, `${name}: ${actual} in node-mavlink, ${expected} here`)
    const clazz = REGISTRY[h.msgid]
    if (!clazz) return differ(i, 'no message of this id in node-mavlink')
    if (clazz.MAGIC_NUMBER !== rec.crc_extra) differ(i, `CRC_EXTRA: ${clazz.MAGIC_NUMBER} in node-mavlink, ${rec.crc_extra} here`)
    if (clazz.PAYLOAD_LENGTH !== rec.max_length) differ(i, `payload length: ${clazz.PAYLOAD_LENGTH} in node-mavlink, ${rec.max_length} here`)
    if (rec.signed) {
      if (!packet.signature) return differ(i, 'no signature in node-mavlink')
      if (!packet.signature.matches(key)) differ(i, 'signature does not match the key in node-mavlink')
      if (packet.signature.linkId !== rec.link_id) differ(i, `link id ${packet.signature.linkId}`)
      if (packet.signature.timestamp !== rec.timestamp) differ(i, `timestamp ${packet.signature.timestamp}`)
    } else if (packet.signature) {
      differ(i, 'signature on an unsigned frame')
    }
    const data = packet.protocol.data(packet.payload, clazz)
    for (const field of clazz.FIELDS) {
      if (!(field.source in rec.fields)) { differ(i, `field ${field.source} not written here`); continue }
      const actual = data[field.name]
      if (!same(field, actual, rec.fields[field.source])) {
        differ(i, `field ${field.source}: ${String(actual)} in node-mavlink, ${JSON.stringify(rec.fields[field.source])} here`)
      }
    }
  })
  if (differences) process.exit(1)
  console.log(`node-mavlink read ${packets.length} frames: ids, lengths, CRCs, CRC_EXTRA, signatures and fields agree`)
}

function encode() {
  const f = Math.fround
  const set = (clazz, values) => Object.assign(new clazz(), values)
  const messages = [
    set(minimal.Heartbeat, { type: 6, autopilot: 8, baseMode: 0, customMode: 0, systemStatus: 4, mavlinkVersion: 3 }),
    set(common.ParamRequestList, { targetSystem: 1, targetComponent: 0 }),
    set(common.ParamRequestRead, { targetSystem: 1, targetComponent: 180, paramId: 'PMU_BAT_B_CAP', paramIndex: -1 }),
    set(common.ParamRequestRead, { targetSystem: 1, targetComponent: 180, paramId: '', paramIndex: 3 }),
    set(common.ParamSet, { targetSystem: 1, targetComponent: 180, paramId: 'ABCDEFGHIJKLMNOP', paramValue: f(27.9), paramType: 9 }),
    set(common.ParamValue, { paramId: 'PMU_OUT_AV', paramValue: f(-1.25), paramType: 9, paramCount: 4, paramIndex: 2 }),
    set(common.CommandLong, { targetSystem: 1, targetComponent: 180, command: 223, confirmation: 0,
      param1: 1, param2: 0, param3: f(2.5), param4: 1, param5: 0, param6: 0, param7: 0 }),
    set(common.CommandLong, { targetSystem: 1, targetComponent: 180, command: 511, confirmation: 3,
      param1: 373, param2: 100000, param3: f(NaN), param4: f(-0.1), param5: 0, param6: 0, param7: f(3.4e38) }),
    set(common.CommandLong, { targetSystem: 1, targetComponent: 180, command: 181, confirmation: 0,
      param1: 2, param2: 1, param3: 0, param4: 0, param5: 0, param6: 0, param7: 0 }),
    set(common.CommandAck, { command: 246, result: 5, progress: 255, resultParam2: -2, targetSystem: 255, targetComponent: 190 }),
    set(common.StatusText, { severity: 2, text: 'x'.repeat(50), id: 0, chunkSeq: 0 }),
    set(common.BatteryStatus, { id: 11, batteryFunction: 3, type: 2, temperature: -300,
      voltages: [3300, 3301, 3302, 3303, 65535, 65535, 65535, 65535, 65535, 65535], currentBattery: 1234,
      currentConsumed: -1, energyConsumed: 77, batteryRemaining: 5, timeRemaining: 1, chargeState: 4,
      voltagesExt: [1, 2, 3, 4], mode: 2, faultBitmask: 0x1ff }),
    set(common.GeneratorStatus, { status: 1n << 63n | 524288n, generatorSpeed: 65535, batteryCurrent: f(NaN),
      loadCurrent: f(0.5), powerGenerated: f(1e-3), busVoltage: f(48.2), rectifierTemperature: 32767,
      batCurrentSetpoint: f(-7.75), generatorTemperature: 90, runtime: 4294967295, timeUntilMaintenance: 2147483647 }),
  ]
  const plain = new MavLinkProtocolV2(255, 190)
  const signing = new MavLinkProtocolV2(255, 190, MavLinkProtocolV2.IFLAG_SIGNED)
  const start = Date.UTC(2026, 0, 1)
  let seq = 0
  let stamp = 0
  for (const message of messages) {
    for (const signed of [false, true]) {
      const clazz = message.constructor
      let buffer = (signed ? signing : plain).serialize(message, seq)
      let timestamp = 0
      if (signed) {
        // Milliseconds: one more per frame, so the stream's timestamps increase.
        buffer = signing.sign(buffer, 6, key, start + stamp++)
        timestamp = buffer.readUIntLE(buffer.length - 12, 6)
      }
      const fields = {}
      for (const field of clazz.FIELDS) {
        const v = message[field.name]
        fields[field.source] = typeof v === 'bigint' ? v.toString()
          : (typeof v === 'number' && Number.isNaN(v)) ? 'NaN' : v
      }
      const crcAt = buffer.length - (signed ? 13 : 0) - 2
      console.log(JSON.stringify({
        hex: buffer.toString('hex'), msgid: clazz.MSG_ID, sysid: 255, compid: 190, seq,
        payload_length: buffer[1], crc: buffer.readUInt16LE(crcAt), crc_extra: clazz.MAGIC_NUMBER,
        max_length: clazz.PAYLOAD_LENGTH, signed, link_id: signed ? 6 : 0, timestamp, fields,
      }))
      seq = (seq + 1) & 255
    }
  }
}

if (mode === 'decode') await decode()
else encode()
