"""Soak run of the robot cell example: DrillHole many times in a row, every skill state watched.

usage: .venv/bin/python tests/interop/skills_soak.py --robot URL --unit URL --cell URL [--runs 1000] [--server-pid PID]

One python asyncua session per server, each with one subscription to CurrentState (sampling interval 0,
queue 100) and to the SkillTransitionEventType events of every skill in its SkillSet: the robot's three
move skills, the drilling unit's TemplateDrilling, the cell's DrillHole and ReferenceDrillBush. Then
DrillHole is started ``--runs`` times, each as soon as the one before is back in Ready.

It fails unless every Start is Good, every run ends in Ready with Result Good, and the transition events of
all skills, ordered by their Time, are exactly ``--runs`` repetitions of DrillHole Running, move Running,
move Ready, drill Running, drill Ready, move Running, move Ready, DrillHole Ready (no event missing, none
extra, no other skill moving), and every skill's CurrentState notifications alternate as its transitions
do. With ``--server-pid`` it reports the server process's resident memory after 10%, 50% and 100% of the
runs, and fails if it grew by more than 16 MiB from 10% to the end (16 KiB per run over 1,000 runs).

The last line is ``SOAK key=value ...``.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import statistics
import sys
import time

from asyncua import Client, ua

from skills_check import (
    CELL_SKILLS,
    DRILL_HOLE_EVENTS,
    ROBOT_SKILLS,
    UNIT_SKILLS,
    children,
    double,
    find,
    skill_events,
)

logging.basicConfig(level=logging.ERROR)

PATTERN = DRILL_HOLE_EVENTS


class Watch:
    """Everything the subscriptions saw."""

    def __init__(self) -> None:
        self.names: dict = {}  # skill node -> skill name
        self.state_nodes: dict = {}  # CurrentState node -> skill name
        self.states: dict = {}  # skill name -> CurrentState values
        self.events: list = []  # (Time, "Skill ToState")
        self.ready = asyncio.Event()
        self.hole_ready = 0
        self.bad_status: list = []

    def datachange_notification(self, node, val, data):
        # (Only CurrentState: async-opcua 0.19 also sends each event item one BadWaitingForInitialData value.)
        name = self.state_nodes.get(node.nodeid)
        if name is not None:
            self.states[name].append(val.Text if isinstance(val, ua.LocalizedText) else str(val))

    def event_notification(self, event):
        fields = event.get_event_props_as_fields_dict()
        source = fields.get("SourceNode")
        name = self.names.get(source.Value if source is not None else None)
        to_state = getattr(getattr(fields.get("ToState"), "Value", None), "Text", None)
        self.events.append((fields["Time"].Value, f"{name} {to_state}"))
        if name == "DrillHole" and to_state in ("Ready", "Halted"):
            self.hole_ready += 1
            self.ready.set()

    def status_change_notification(self, status):
        self.bad_status.append(str(status))


async def subscribe(client: Client, watch: Watch, path: list) -> dict:
    sub = await client.create_subscription(20, watch)
    event_type, evfilter = await skill_events(client)
    skills = await children(client, await find(client, path))
    out = {}
    for name, node in skills.items():
        kids = await children(client, node)
        watch.names[node] = name
        watch.state_nodes[kids["CurrentState"]] = name
        watch.states[name] = []
        await sub.subscribe_data_change(client.get_node(kids["CurrentState"]), queuesize=100, sampling_interval=0)
        await sub.subscribe_events(client.get_node(node), event_type, evfilter=evfilter, queuesize=1000)
        out[name] = (node, kids)
    return out


def rss_kib(pid: int | None) -> int | None:
    if pid is None:
        return None
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return None


def alternates(values: list, transitions: int) -> bool:
    """CurrentState: the initial Ready, then Running/Ready pairs, one value per transition."""
    expected = ["Ready"] + ["Running", "Ready"] * (transitions // 2)
    return values == expected


async def soak(robot_url: str, unit_url: str, cell_url: str, runs: int, pid: int | None) -> int:
    clients = [Client(url=u, timeout=10) for u in (robot_url, unit_url, cell_url)]
    for c in clients:
        await c.connect()
    robot, unit, cell = clients
    watch = Watch()
    try:
        await subscribe(robot, watch, ROBOT_SKILLS)
        await subscribe(unit, watch, UNIT_SKILLS)
        cell_skills = await subscribe(cell, watch, CELL_SKILLS)
        hole, kids = cell_skills["DrillHole"]
        inputs = await children(cell, kids["InputParameterSet"])
        for name, value in [
            ("InsertionDistance", 12.5),
            ("HoleDiameter", 6),
            ("Depth", 8),
            ("FeedRate", 120),
            ("SpindleSpeed", 3000),
            ("ClampForce", 400),
        ]:
            await cell.get_node(inputs[name]).write_value(ua.DataValue(double(value)))
        result = (await children(cell, kids["OutputParameterSet"]))["Result"]
        await asyncio.sleep(0.5)

        failures: list = []
        durations: list = []
        memory: dict = {}
        started = time.monotonic()
        for i in range(runs):
            watch.ready.clear()
            t0 = time.monotonic()
            try:
                await cell.get_node(hole).call_method(kids["Start"])
            except ua.UaStatusCodeError as e:
                failures.append(f"run {i + 1}: Start answered {ua.StatusCode(e.code)}")
                break
            while watch.hole_ready < i + 1:
                try:
                    await asyncio.wait_for(watch.ready.wait(), 30)
                except asyncio.TimeoutError:
                    failures.append(f"run {i + 1}: DrillHole did not end within 30 s")
                    break
                watch.ready.clear()
            if failures:
                break
            durations.append(time.monotonic() - t0)
            outcome = await cell.get_node(result).read_value()
            if not (isinstance(outcome, ua.StatusCode) and outcome.is_good()):
                failures.append(f"run {i + 1}: Result {outcome}")
                break
            for share in (10, 50, 100):
                if i + 1 == max(1, runs * share // 100) and pid is not None:
                    memory[share] = rss_kib(pid)
        elapsed = time.monotonic() - started
        await asyncio.sleep(1.0)  # the last notifications

        order = [e for _, e in sorted(watch.events, key=lambda x: x[0])]
        done = len(durations)
        if order != PATTERN * done:
            first = next((k for k, (a, b) in enumerate(zip(order, PATTERN * done)) if a != b), min(len(order), len(PATTERN) * done))
            failures.append(
                f"transition events: {len(order)} for {done} runs (expected {len(PATTERN) * done}); first difference at event {first}: "
                f"{order[max(0, first - 3):first + 5]}"
            )
        per_run = {"DrillHole": 2, "RelativeCartesianLinearMove": 4, "TemplateDrilling": 2}
        for name, values in sorted(watch.states.items()):
            if not alternates(values, per_run.get(name, 0) * done):
                failures.append(f"CurrentState of {name}: {len(values)} notifications, expected {1 + per_run.get(name, 0) * done}: {values[:5]}")
        if watch.bad_status:
            failures.append(f"subscription status changes: {watch.bad_status[:3]}")

        for f in failures:
            print(f"FAIL {f}", flush=True)
        ms = sorted(d * 1000 for d in durations) or [0.0]
        p99 = ms[min(len(ms) - 1, int(len(ms) * 0.99))]
        print(
            f"{done} of {runs} DrillHole runs in {elapsed:.1f} s ({done / elapsed if elapsed else 0:.1f}/s); "
            f"per run median {statistics.median(ms):.1f} ms, p99 {p99:.1f} ms; "
            f"{len(watch.events)} transition events, {sum(len(v) for v in watch.states.values())} CurrentState notifications"
        )
        if memory:
            print("server RSS: " + ", ".join(f"{k}% {v / 1024:.1f} MiB" for k, v in sorted(memory.items())))
            if 10 in memory and 100 in memory and memory[100] - memory[10] > 16 * 1024:
                failures.append("memory")
                print(f"FAIL server RSS grew by {(memory[100] - memory[10]) / 1024:.1f} MiB from 10% to 100% of the runs")
        mem = " ".join(f"rss{k}_kib={v}" for k, v in sorted(memory.items()))
        print(f"SOAK runs={done} events={len(watch.events)} failures={len(failures)} seconds={elapsed:.1f} {mem}".rstrip())
        return 1 if failures else 0
    finally:
        for c in clients:
            await c.disconnect()


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--robot", required=True)
    parser.add_argument("--unit", required=True)
    parser.add_argument("--cell", required=True)
    parser.add_argument("--runs", type=int, default=1000)
    parser.add_argument("--server-pid", type=int)
    args = parser.parse_args()
    return asyncio.run(soak(args.robot, args.unit, args.cell, args.runs, args.server_pid))


if __name__ == "__main__":
    sys.exit(main())
