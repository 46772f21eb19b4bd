#!/usr/bin/env python3
"""List a shipcast log's channels and decode one message of each, with the off-the-shelf `mcap` reader.

    python3 -m pip install -r tools/replay/requirements.txt
    python3 tools/replay/list_log.py LOG.mcap

Prints one JSON object per channel: topic, message encoding, schema name and encoding, the schema's
top-level field names, number of messages, the first log time (ISO 8601, UTC) and the first message
decoded (long arrays shortened); then one object per metadata record (`{"metadata": name, ...}`).
Exits non-zero if the file cannot be read.
"""

import datetime
import json
import sys

from mcap.reader import make_reader


def shorten(v):
    if isinstance(v, list) and len(v) > 8:
        return [shorten(x) for x in v[:4]] + [f"... {len(v)} items"]
    if isinstance(v, list):
        return [shorten(x) for x in v]
    if isinstance(v, dict):
        return {k: shorten(x) for k, x in v.items()}
    return v


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1], "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        counts = summary.statistics.channel_message_counts if summary and summary.statistics else {}
        first = {}
        for schema, channel, message in reader.iter_messages():
            if channel.id not in first:
                first[channel.id] = (schema, channel, message.log_time, json.loads(message.data))
        for cid, (schema, channel, log_time, msg) in sorted(first.items()):
            fields = []
            if schema and schema.encoding == "jsonschema" and schema.data:
                fields = list(json.loads(schema.data).get("properties", {}))
            when = datetime.datetime.fromtimestamp(log_time / 1e9, tz=datetime.timezone.utc)
            print(json.dumps({
                "topic": channel.topic,
                "encoding": channel.message_encoding,
                "schema": schema.name if schema else None,
                "schema_encoding": schema.encoding if schema else None,
                "fields": fields,
                "schema_version": channel.metadata.get("shipcast_schema_version"),
                "messages": counts.get(cid),
                "first_log_time": when.isoformat(),
                "first": shorten(msg),
            }))
        for m in reader.iter_metadata():
            print(json.dumps({"metadata": m.name, **m.metadata}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
