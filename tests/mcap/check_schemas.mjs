// Checks the `omgidl` schemas of an MCAP file of pmuctl (docs/interface.md section 9.1) with the
// ecosystem's own code (@mcap/core, @foxglove/omgidl-parser, @foxglove/omgidl-serialization):
// each schema parses; it defines its own struct, named as the schema, and every other
// definition in it is one that struct uses (through its fields, transitively), each exactly
// once; a message of each channel decodes with it into the struct's fields. Prints the
// schemas' sizes and their total.
//   node check_schemas.mjs FILE.mcap [--max-total BYTES]
// Exit status 0 when every check passed; 1 with the problems on stderr.
import { open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";

const args = process.argv.slice(2);
const file = args[0];
const maxIndex = args.indexOf("--max-total");
const maxTotal = maxIndex >= 0 ? Number(args[maxIndex + 1]) : Infinity;
const problems = [];
const problem = (p) => problems.push(p);

const handle = await open(file, "r");
const size = (await handle.stat()).size;
const reader = await McapIndexedReader.Initialize({
  readable: {
    size: async () => BigInt(size),
    read: async (offset, length) => {
      const buf = new Uint8Array(Number(length));
      await handle.read(buf, 0, Number(length), Number(offset));
      return buf;
    },
  },
});

const escape = (s) => s.replace(/[.*+?^${}()|[\]\\]/g, "\\$&");
const parsed = new Map(); // schema id -> {name, definitions, root}
let total = 0;
const sizes = [];
for (const [id, schema] of reader.schemasById) {
  const text = new TextDecoder().decode(schema.data);
  total += schema.data.length;
  sizes.push(`${schema.name} ${schema.data.length}`);
  let definitions;
  try {
    definitions = parseIDL(text);
  } catch (e) {
    problem(`${schema.name}: does not parse: ${e.message}`);
    continue;
  }
  const byName = new Map(definitions.map((d) => [d.name, d]));
  const root = byName.get(schema.name);
  if (!root || root.aggregatedKind !== "struct") {
    problem(`${schema.name}: the schema does not define the struct ${schema.name}`);
    continue;
  }
  // What the struct uses: its fields' struct and enum types, transitively.
  const used = new Set();
  const visit = (d) => {
    if (used.has(d.name)) return;
    used.add(d.name);
    for (const f of d.definitions ?? []) {
      for (const t of [f.isComplex ? f.type : null, f.enumType]) {
        if (!t) continue;
        const target = byName.get(t);
        if (!target) problem(`${schema.name}: ${d.name}.${f.name} names ${t}, which the schema does not define`);
        else visit(target);
      }
    }
  };
  visit(root);
  for (const d of definitions)
    if (!used.has(d.name)) problem(`${schema.name}: defines ${d.name}, which ${schema.name} does not use`);
  // Each definition written once in the text (a parser may keep only one of two).
  for (const d of definitions) {
    const short = d.name.split("::").at(-1);
    const n = text.match(new RegExp(`\\b(struct|enum|union|typedef[^;]*)\\s+${escape(short)}\\b`, "g"))?.length ?? 0;
    if (n !== 1) problem(`${schema.name}: ${short} is defined ${n} times in the text`);
  }
  parsed.set(id, { name: schema.name, definitions, root });
}

// One message of each channel, decoded with its schema into the struct's fields.
const decoded = new Set();
for await (const m of reader.readMessages()) {
  if (decoded.has(m.channelId)) continue;
  decoded.add(m.channelId);
  const channel = reader.channelsById.get(m.channelId);
  const schema = parsed.get(channel.schemaId);
  if (!schema) continue;
  try {
    const values = new MessageReader(schema.name, schema.definitions).readMessage(m.data);
    const want = schema.root.definitions.filter((f) => !f.isConstant).map((f) => f.name);
    if (JSON.stringify(Object.keys(values)) !== JSON.stringify(want))
      problem(`${channel.topic}: decoded fields ${Object.keys(values)}, the struct has ${want}`);
  } catch (e) {
    problem(`${channel.topic}: a message does not decode with ${schema.name}: ${e.message}`);
  }
}
await handle.close();

if (total > maxTotal) problem(`the ${reader.schemasById.size} schemas take ${total} bytes, more than ${maxTotal}`);
if (problems.length) {
  console.error(problems.slice(0, 30).join("\n"));
  process.exit(1);
}
console.log(`check_schemas: ${reader.schemasById.size} schemas, ${total} bytes (${sizes.join(", ")}); ${decoded.size} channels' messages decoded`);
