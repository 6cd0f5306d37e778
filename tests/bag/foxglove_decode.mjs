// Read one MCAP file the way Foxglove and Lichtblick do and print what they see as JSON lines.
//
//   node foxglove_decode.mjs MODULES_DIR FILE.mcap
//
// MODULES_DIR is the npm prefix the test setup installed into (its node_modules holds
// @mcap/core, @foxglove/rosmsg, @foxglove/ros2idl-parser, @foxglove/rosmsg2-serialization,
// @foxglove/wasm-zstd and @foxglove/wasm-lz4). The file is opened with McapIndexedReader
// (compressed chunks through the wasm decompressors), each channel's schema is parsed as the
// viewers parse it (`ros2msg` with rosmsg's ros2 mode, `ros2idl` with ros2idl-parser) and every
// message is decoded with rosmsg2-serialization's MessageReader. Lines:
//   {"kind": "header", "profile", "library"}
//   {"kind": "channel", "id", "topic", "messageEncoding", "schemaName", "schemaEncoding", "metadata"}
//   {"kind": "metadata", "name", "metadata"}                 (each metadata record)
//   {"kind": "message", "topic", "schemaName", "logTime", "publishTime", "sequence",
//    "trailingBytes", "message"}
//   {"kind": "error", "topic", "error"}                       (a channel or message not decoded)
// int64 values are numbers where exact, strings otherwise; typed arrays are plain arrays.
// A file that cannot be opened is one line on stderr and exit code 1.

import { open } from "node:fs/promises";
import { createRequire } from "node:module";
import path from "node:path";

const [modulesDir, file] = process.argv.slice(2);
if (!modulesDir || !file) {
  process.stderr.write("usage: node foxglove_decode.mjs MODULES_DIR FILE.mcap\n");
  process.exit(2);
}
const require = createRequire(path.join(path.resolve(modulesDir), "package.json"));
const { McapIndexedReader } = require("@mcap/core");
const { parse: parseRosMsg } = require("@foxglove/rosmsg");
const { parseRos2idl } = require("@foxglove/ros2idl-parser");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const zstd = require("@foxglove/wasm-zstd");
const lz4 = require("@foxglove/wasm-lz4");

function toJson(value) {
  return JSON.stringify(value, (_key, item) => {
    if (typeof item === "bigint") {
      return Number.isSafeInteger(Number(item)) ? Number(item) : item.toString();
    }
    if (ArrayBuffer.isView(item) && !(item instanceof DataView)) {
      return Array.from(item);
    }
    if (item instanceof Map) {
      return Object.fromEntries(item);
    }
    return item;
  });
}

function emit(record) {
  process.stdout.write(toJson(record) + "\n");
}

function readerFor(channel, schema) {
  if (channel.messageEncoding !== "cdr") {
    throw new Error(`message encoding '${channel.messageEncoding}' is not cdr`);
  }
  if (!schema) {
    throw new Error(`channel ${channel.topic} has no schema (id ${channel.schemaId})`);
  }
  const text = new TextDecoder().decode(schema.data);
  let definitions;
  if (schema.encoding === "ros2msg") {
    definitions = parseRosMsg(text, { ros2: true });
  } else if (schema.encoding === "ros2idl") {
    definitions = parseRos2idl(text);
  } else {
    throw new Error(`schema encoding '${schema.encoding}' is not ros2msg or ros2idl`);
  }
  return new MessageReader(definitions);
}

async function main() {
  await zstd.isLoaded;
  await lz4.isLoaded;
  let handle;
  try {
    handle = await open(file, "r");
  } catch (err) {
    process.stderr.write(`${file}: ${err.message}\n`);
    process.exit(1);
  }
  const readable = {
    size: async () => BigInt((await handle.stat()).size),
    read: async (offset, length) => {
      const buffer = new Uint8Array(Number(length));
      const { bytesRead } = await handle.read(buffer, 0, Number(length), Number(offset));
      if (bytesRead !== Number(length)) {
        throw new Error(`short read at ${offset}: ${bytesRead} of ${length} bytes`);
      }
      return buffer;
    },
  };
  let reader;
  try {
    reader = await McapIndexedReader.Initialize({
      readable,
      decompressHandlers: {
        zstd: (data, size) => zstd.decompress(data, Number(size)),
        lz4: (data, size) => lz4(data, Number(size)),
      },
    });
  } catch (err) {
    process.stderr.write(`${file}: ${err.message}\n`);
    process.exit(1);
  }
  emit({ kind: "header", profile: reader.header.profile, library: reader.header.library });
  const readers = new Map();
  for (const channel of reader.channelsById.values()) {
    const schema = reader.schemasById.get(channel.schemaId);
    emit({
      kind: "channel",
      id: channel.id,
      topic: channel.topic,
      messageEncoding: channel.messageEncoding,
      schemaName: schema?.name ?? null,
      schemaEncoding: schema?.encoding ?? null,
      metadata: channel.metadata,
    });
    try {
      readers.set(channel.id, { reader: readerFor(channel, schema), schema });
    } catch (err) {
      emit({ kind: "error", topic: channel.topic, error: String(err.message ?? err) });
    }
  }
  for await (const record of reader.readMetadata()) {
    emit({ kind: "metadata", name: record.name, metadata: record.metadata });
  }
  for await (const message of reader.readMessages({ validateCrcs: true })) {
    const channel = reader.channelsById.get(message.channelId);
    const entry = readers.get(message.channelId);
    if (!entry) {
      continue; // its channel's error line is out already
    }
    try {
      const decoded = entry.reader.readMessage(message.data);
      emit({
        kind: "message",
        topic: channel.topic,
        schemaName: entry.schema.name,
        logTime: message.logTime.toString(),
        publishTime: message.publishTime.toString(),
        sequence: message.sequence,
        trailingBytes: entry.reader.lastReadHadTrailingBytes(),
        message: decoded,
      });
    } catch (err) {
      emit({ kind: "error", topic: channel.topic, error: String(err.message ?? err) });
    }
  }
  await handle.close();
}

await main();
