// Foxglove's published WebSocket client (@foxglove/ws-protocol) and ROS 2 decoder
// (@foxglove/rosmsg, @foxglove/rosmsg2-serialization), as the Foxglove app and Lichtblick use them.
//
//   node client.mjs URL SUBPROTOCOL TOPIC:COUNT[,TOPIC:COUNT...]
//
// Connects offering SUBPROTOCOL only, subscribes to each TOPIC once advertised, decodes COUNT
// messages of it from the ros2msg schema the server advertised, prints one JSON line per
// decoded message ({topic, schemaName, subprotocol, logTimeNs, message}), and exits 0; any
// error (HTTP refusal of the subprotocol, a schema or payload that does not decode) exits 1.
import wsProtocol from "@foxglove/ws-protocol";
import rosmsg from "@foxglove/rosmsg";
import serialization from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol; // CommonJS packages: their exports through the default one
const { parse } = rosmsg;
const { MessageReader } = serialization;

const [url, subprotocol, topicList] = process.argv.slice(2);
const counts = new Map(topicList.split(",").map((item) => [item.slice(0, item.lastIndexOf(":")), Number(item.slice(item.lastIndexOf(":") + 1))]));
const wanted = new Set(counts.keys());
const ws = new WebSocket(url, [subprotocol]);
const client = new FoxgloveClient({ ws });
const readers = new Map(); // subscription id -> {topic, schemaName, reader}
const received = new Map([...wanted].map((t) => [t, 0]));

let done = false;
// process.exit drops what a pipe has not taken yet: exit once stdout and stderr are flushed.
const exit = (code) => process.stdout.write("", () => process.stderr.write("", () => process.exit(code)));
const fail = (why) => {
  if (done) return;
  done = true;
  console.error(`client: ${why}`);
  exit(1);
};
const plain = (_key, value) => (typeof value === "bigint" ? value.toString() : ArrayBuffer.isView(value) ? Array.from(value) : value);

ws.on("unexpected-response", (_req, res) => fail(`HTTP ${res.statusCode} for subprotocol ${subprotocol}`));
client.on("error", (error) => fail(String(error?.message ?? error)));
client.on("close", () => fail("connection closed"));
client.on("advertise", (channels) => {
  for (const channel of channels) {
    if (!wanted.has(channel.topic) || [...readers.values()].some((r) => r.topic === channel.topic)) continue;
    if (channel.encoding !== "cdr" || channel.schemaEncoding !== "ros2msg") fail(`${channel.topic}: ${channel.encoding}/${channel.schemaEncoding}`);
    const reader = new MessageReader(parse(channel.schema, { ros2: true }));
    readers.set(client.subscribe(channel.id), { topic: channel.topic, schemaName: channel.schemaName, reader });
  }
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const entry = readers.get(subscriptionId);
  if (done || !entry || received.get(entry.topic) >= counts.get(entry.topic)) return;
  const message = entry.reader.readMessage(data);
  received.set(entry.topic, received.get(entry.topic) + 1);
  const line = { topic: entry.topic, schemaName: entry.schemaName, subprotocol: ws.protocol, logTimeNs: timestamp, message };
  console.log(JSON.stringify(line, plain));
  if ([...received].every(([topic, n]) => n >= counts.get(topic))) {
    done = true;
    client.close();
    exit(0);
  }
});
