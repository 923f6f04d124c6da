// Reads an MCAP file with the ecosystem's own code and prints one JSON line per message:
//   {"topic", "schema", "sequence", "log_time", "publish_time" (ns, as strings), "values"}
// then {"end": {...}} with what the reader saw. The file is read by @mcap/core (the indexed
// reader: magic, footer, summary, chunk indexes, CRCs; with --stream the stream reader,
// which is what a viewer falls back to for a file without a summary, e.g. after a crash),
// each channel's schema is parsed by @foxglove/omgidl-parser and every message decoded by
// @foxglove/omgidl-serialization's MessageReader, as Foxglove and Lichtblick do; a `ros2msg`
// schema (the ROS 2 topics) by @foxglove/rosmsg's parser and @foxglove/rosmsg2-serialization's
// MessageReader, as Foxglove reads ROS 2 channels.
//
//   node read_mcap.mjs FILE.mcap [--stream]
// FILE "-" is standard input, read to its end (`pmuctl record - | node read_mcap.mjs - --stream`).
// Exit status 0 when every message decoded, 1 otherwise (the reason on stderr).
import { readFile, open } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { parse as parseRosmsg } from "@foxglove/rosmsg";
import { MessageReader as Ros2MessageReader } from "@foxglove/rosmsg2-serialization";

const args = process.argv.slice(2);
const stream = args.includes("--stream");
const file = args.find((a) => a === "-" || !a.startsWith("-"));
if (!file) {
  console.error("usage: node read_mcap.mjs FILE.mcap [--stream]");
  process.exit(2);
}

const schemas = new Map(); // schema id -> {name, encoding, data}
const readers = new Map(); // channel id -> {topic, schema, reader}
const channels = new Map();

async function readAll(name) {
  if (name !== "-") return readFile(name);
  const parts = [];
  for await (const part of process.stdin) parts.push(part);
  return Buffer.concat(parts);
}

function readerFor(channelId) {
  if (readers.has(channelId)) return readers.get(channelId);
  const channel = channels.get(channelId);
  if (!channel) throw new Error(`message on unknown channel ${channelId}`);
  const schema = schemas.get(channel.schemaId);
  if (!schema) throw new Error(`channel ${channel.topic} names unknown schema ${channel.schemaId}`);
  if (channel.messageEncoding !== "cdr" || (schema.encoding !== "omgidl" && schema.encoding !== "ros2msg"))
    throw new Error(`channel ${channel.topic}: encodings ${channel.messageEncoding}/${schema.encoding}, not cdr/omgidl or cdr/ros2msg`);
  const text = new TextDecoder().decode(schema.data);
  const reader =
    schema.encoding === "ros2msg"
      ? new Ros2MessageReader(parseRosmsg(text, { ros2: true }))
      : new MessageReader(schema.name, parseIDL(text));
  const r = { topic: channel.topic, schema: schema.name, reader };
  readers.set(channelId, r);
  return r;
}

// Floats are float32 on the wire: print them as the shortest decimal that rounds to the same
// float32, so they compare with pmuctl's JSON without noise.
function tidy(v) {
  if (typeof v === "number" && !Number.isInteger(v) && Number.isFinite(v)) return Number(Math.fround(v).toPrecision(7));
  if (typeof v === "bigint") return v.toString();
  if (Array.isArray(v)) return v.map(tidy);
  if (v && typeof v === "object" && !(v instanceof Uint8Array)) {
    const o = {};
    for (const [k, x] of Object.entries(v)) o[k] = tidy(x);
    return o;
  }
  return v;
}

let count = 0;
function emit(m) {
  const r = readerFor(m.channelId);
  const values = r.reader.readMessage(m.data);
  count++;
  process.stdout.write(
    JSON.stringify({
      topic: r.topic,
      schema: r.schema,
      sequence: m.sequence,
      log_time: m.logTime.toString(),
      publish_time: m.publishTime.toString(),
      values: tidy(values),
    }) + "\n",
  );
}

try {
  const end = { reader: stream ? "stream" : "indexed" };
  if (stream) {
    const reader = new McapStreamReader({ validateCrcs: true });
    reader.append(await readAll(file));
    let rec;
    let footer = false;
    while ((rec = reader.nextRecord())) {
      if (rec.type === "Schema") schemas.set(rec.id, rec);
      else if (rec.type === "Channel") channels.set(rec.id, rec);
      else if (rec.type === "Message") emit(rec);
      else if (rec.type === "Footer") footer = true;
    }
    end.footer = footer;
    end.complete = reader.done();
  } else {
    // A file is read where it lies, as a viewer does; standard input from memory.
    const bytes = file === "-" ? await readAll(file) : null;
    const handle = bytes ? null : await open(file, "r");
    const size = bytes ? bytes.length : (await handle.stat()).size;
    const readable = {
      size: async () => BigInt(size),
      read: async (offset, length) => {
        if (bytes) return new Uint8Array(bytes.buffer, bytes.byteOffset + Number(offset), Number(length));
        const buf = new Uint8Array(Number(length));
        await handle.read(buf, 0, Number(length), Number(offset));
        return buf;
      },
    };
    const reader = await McapIndexedReader.Initialize({ readable });
    for (const [id, s] of reader.schemasById) schemas.set(id, s);
    for (const [id, c] of reader.channelsById) channels.set(id, c);
    for await (const m of reader.readMessages({ validateCrcs: true })) emit(m);
    const st = reader.statistics;
    end.chunks = reader.chunkIndexes.length;
    end.statistics = st
      ? { message_count: st.messageCount.toString(), channel_count: st.channelCount, chunk_count: st.chunkCount }
      : null;
    end.topics = [...reader.channelsById.values()].map((c) => c.topic);
    end.schemas = [...reader.schemasById.values()].map((x) => ({ name: x.name, encoding: x.encoding }));
    if (handle) await handle.close();
  }
  end.messages = count;
  process.stdout.write(JSON.stringify({ end }) + "\n");
} catch (e) {
  console.error(`read_mcap.mjs: ${file}: ${e && e.message ? e.message : e}`);
  process.exit(1);
}
