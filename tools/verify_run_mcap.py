#!/usr/bin/env python3
"""Checks a `run.mcap` written by `pipeline run` independently of the Rust code that wrote it.

Reads every message with the `mcap` package (pip install mcap), decodes it as JSON, and checks
the channel set, the encodings, one message per station on every channel (station i at i
seconds), and the keys each message must carry (docs/RUN_OUTPUTS.md). Prints a short summary;
exits 1 on any problem.

    python3 tools/verify_run_mcap.py OUT/run.mcap
"""

import json
import sys
from collections import defaultdict

from mcap.reader import make_reader

# Keys of each message, and of the items of its per-detection (or per-landmark/edge) lists.
EXPECTED = {
    "/detections": (
        {"index", "station", "detections"},
        {"detections": {"detection", "bbox", "centroid", "contact_row", "pixels", "stereo_column"}},
    ),
    "/bearings": (
        {"index", "station", "bearings"},
        {"bearings": {"detection", "bearing", "uncertainty"}},
    ),
    "/range_order": (
        {"index", "station", "ranges", "nearer"},
        {"ranges": {"detection", "ground", "stereo", "size", "fused", "conflict"}},
    ),
    "/association": (
        {"index", "station", "associations", "registrations"},
        {"associations": {"detection", "decision"},
         "registrations": {"frame", "pairs", "nfa", "believed"}},
    ),
    "/measurements": (
        {"index", "station", "files", "landmarks", "triples", "relations_tightened",
         "resolved_held_back", "recognised", "revisited", "contradiction", "warnings"},
        {},
    ),
    "/map_metrics": (
        {"index", "station", "landmarks", "triples", "open_fraction",
         "fully_constrained_fraction", "rng_certain", "rng_uncertain", "rng_cost", "seconds"},
        {},
    ),
    "/rng": (
        {"index", "landmarks", "edges"},
        {"landmarks": {"landmark", "position"}, "edges": {"from", "to", "cost"}},
    ),
}
DECISIONS = {"matched", "new", "held_back", "unused"}
STAGES = {"decode", "detect", "range", "associate", "map", "metrics"}
NANOSECONDS = 1_000_000_000


def verify(path):
    """Returns (problems, summary lines)."""
    problems = []
    by_topic = defaultdict(dict)  # topic -> station index -> message
    with open(path, "rb") as f:
        reader = make_reader(f)
        channels = reader.get_summary().channels.values()
        topics = {c.topic for c in channels}
        if topics != set(EXPECTED):
            problems.append(f"channels {sorted(topics)}, expected {sorted(EXPECTED)}")
        for schema, channel, message in reader.iter_messages():
            where = f"{channel.topic} at {message.log_time} ns"
            if channel.message_encoding != "json":
                problems.append(f"{where}: message encoding {channel.message_encoding!r}")
            if schema is None or schema.encoding != "jsonschema":
                problems.append(f"{where}: no jsonschema schema")
            else:
                try:
                    json.loads(schema.data)
                except ValueError as e:
                    problems.append(f"{channel.topic}: schema is not JSON ({e})")
            try:
                value = json.loads(message.data)
            except ValueError as e:
                problems.append(f"{where}: not JSON ({e})")
                continue
            if not isinstance(value, dict) or not isinstance(value.get("index"), int):
                problems.append(f"{where}: no station index")
                continue
            index = value["index"]
            if message.log_time != index * NANOSECONDS or message.publish_time != message.log_time:
                problems.append(f"{where}: station {index} should be at {index} s")
            if index in by_topic[channel.topic]:
                problems.append(f"{where}: a second message for station {index}")
            by_topic[channel.topic][index] = value
            problems += check_keys(channel.topic, value, where)

    stations = len(by_topic.get("/detections", {}))
    if stations == 0:
        problems.append("no stations")
    for topic in sorted(EXPECTED):
        indices = sorted(by_topic.get(topic, {}))
        if indices != list(range(stations)):
            problems.append(f"{topic}: stations {indices}, expected 0..{stations - 1}")
    for index, detections in by_topic.get("/detections", {}).items():
        count = len(detections.get("detections", []))
        for topic, key in [("/bearings", "bearings"), ("/range_order", "ranges"),
                           ("/association", "associations")]:
            other = by_topic.get(topic, {}).get(index, {}).get(key, [])
            if len(other) != count:
                problems.append(f"{topic} station {index}: {len(other)} entries, {count} detections")

    summary = [f"{path}: {stations} stations, {len(topics)} channels, "
               f"{sum(len(m) for m in by_topic.values())} messages"]
    if stations:
        detections = sum(len(m.get("detections", [])) for m in by_topic["/detections"].values())
        decisions = defaultdict(int)
        for m in by_topic.get("/association", {}).values():
            for a in m.get("associations", []):
                decisions[a.get("decision")] += 1
        last = by_topic.get("/map_metrics", {}).get(stations - 1, {})
        rejected = sum(1 for m in by_topic.get("/measurements", {}).values() if m.get("contradiction"))
        summary.append(f"  detections {detections} ({', '.join(f'{k} {v}' for k, v in sorted(decisions.items()))})")
        registrations = [r for m in by_topic.get("/association", {}).values()
                         for r in m.get("registrations", [])]
        believed = sum(1 for r in registrations if r.get("believed"))
        summary.append(f"  registrations {len(registrations)} ({believed} believed)")
        summary.append(f"  stations rejected by the map: {rejected}")
        summary.append(f"  the last station's map: {last.get('landmarks')} landmarks, {last.get('triples')} triples, "
                       f"open {last.get('open_fraction')}, fully constrained "
                       f"{last.get('fully_constrained_fraction')}, RNG cost {last.get('rng_cost')}")
    return problems, summary


def check_keys(topic, value, where):
    problems = []
    keys, items = EXPECTED.get(topic, (set(), {}))
    missing = keys - value.keys()
    if missing:
        problems.append(f"{where}: missing {sorted(missing)}")
    for list_key, item_keys in items.items():
        for i, item in enumerate(value.get(list_key) or []):
            if not isinstance(item, dict) or item_keys - item.keys():
                problems.append(f"{where}: {list_key}[{i}] lacks {sorted(item_keys - set(item or {}))}")
    if topic == "/association":
        for i, a in enumerate(value.get("associations") or []):
            decision = a.get("decision")
            if decision not in DECISIONS:
                problems.append(f"{where}: associations[{i}] decision {decision!r}")
            elif decision in ("matched", "new") and "landmark" not in a:
                problems.append(f"{where}: associations[{i}] {decision} without landmark")
            elif decision == "held_back" and "candidates" not in a:
                problems.append(f"{where}: associations[{i}] held_back without candidates")
        detections = len(value.get("associations") or [])
        for i, r in enumerate(value.get("registrations") or []):
            frame = r.get("frame")
            if frame is not None and not (isinstance(frame, int) and 0 <= frame):
                problems.append(f"{where}: registrations[{i}] frame {frame!r}")
            if frame is not None and isinstance(frame, int) and frame == value.get("index"):
                problems.append(f"{where}: registrations[{i}] registers the station against itself")
            if not isinstance(r.get("believed"), bool):
                problems.append(f"{where}: registrations[{i}] believed is not a boolean")
            for pair in r.get("pairs") or []:
                if not (isinstance(pair, list) and len(pair) == 2 and 0 <= pair[0] < detections):
                    problems.append(f"{where}: registrations[{i}] pair {pair!r} names no detection")
    if topic == "/map_metrics" and STAGES - set(value.get("seconds") or {}):
        problems.append(f"{where}: seconds lacks {sorted(STAGES - set(value.get('seconds') or {}))}")
    return problems


def main():
    if len(sys.argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    try:
        problems, summary = verify(sys.argv[1])
    except Exception as e:  # an unreadable file is one more problem to report, not a traceback
        problems, summary = [f"cannot read {sys.argv[1]}: {type(e).__name__}: {e}"], []
    print("\n".join(summary))
    for problem in problems[:50]:
        print(f"PROBLEM {problem}", file=sys.stderr)
    if problems:
        print(f"{len(problems)} problem(s)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
