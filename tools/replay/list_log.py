#!/usr/bin/env python3
"""List a shipcast log's channels and decode one message of each, with the off-the-shelf `mcap` reader.

    python3 -m pip install -r tools/replay/requirements.txt
    python3 tools/replay/list_log.py LOG.mcap

Prints one JSON object per channel: topic, message encoding, schema name, number of messages, and the
first message decoded (long arrays shortened). Exits non-zero if the file cannot be read.
"""

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
                first[channel.id] = (schema, channel, json.loads(message.data))
        for cid, (schema, channel, msg) in sorted(first.items()):
            print(json.dumps({
                "topic": channel.topic,
                "encoding": channel.message_encoding,
                "schema": schema.name if schema else None,
                "schema_version": channel.metadata.get("shipcast_schema_version"),
                "messages": counts.get(cid),
                "first": shorten(msg),
            }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
