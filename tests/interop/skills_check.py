"""Interoperability check of the robot cell example (skills, composite skills) with python asyncua.

usage: .venv/bin/python tests/interop/skills_check.py --robot URL --unit URL --cell URL

The three servers of ``cargo run -p nodeset-examples --example robot_cell``: the robot's move skills, the
drilling unit's TemplateDrilling and the cell's composite skills. Everything is found by browsing names
from the Objects folder; no NodeId is written here except ns0's well-known ones.

- Each SkillSet lists its skills, and each skill's type derives from ProgramStateMachineType.
- AbsoluteJointPTPMove, started with its input parameters, goes Ready -> Running -> Ready in CurrentState
  (a subscription) with one transition event per step (SkillTransitionEventType, with SkillName), and the
  joints end at the target.
- Halt while Running -> Halted (Result says why); Start while Halted -> BadInvalidState; Reset -> Ready.
- DrillHole runs RelativeCartesianLinearMove, TemplateDrilling and RelativeCartesianLinearMove on the
  other two servers in this order, inside its own Running.
- A Halt of TemplateDrilling (on the drilling unit) while DrillHole runs halts DrillHole with the same
  cause; a Halt of DrillHole halts the TemplateDrilling that runs.

Every check prints PASS or FAIL; the last line is ``N passed, N failed``; the exit status is 1 if any
check failed.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys
import time
import traceback

from asyncua import Client, ua

from report import Report
from asyncua.common.events import get_filter_from_event_type

PROGRAM_STATE_MACHINE_TYPE = ua.NodeId(2391, 0)
HAS_SUBTYPE = ua.NodeId(45, 0)
HAS_TYPE_DEFINITION = ua.NodeId(40, 0)
HIERARCHICAL = ua.NodeId(33, 0)
COMMON_SKILLS = "http://nodeset-compiler.dev/CommonSkills/"

SYSTEM = ["DeviceSet", "TemplateDrillingLwrSystem"]
ROBOT_SKILLS = SYSTEM + ["MotionDeviceSystem", "Controllers", "URController", "SkillSet"]
UNIT_SKILLS = SYSTEM + ["DrillingEndEffector", "SkillSet"]
CELL_SKILLS = ["DrillingCell", "SkillSet"]
# One DrillHole run as transition events of the three servers' skills, in Time order.
DRILL_HOLE_EVENTS = [
    "DrillHole Running",
    "RelativeCartesianLinearMove Running",
    "RelativeCartesianLinearMove Ready",
    "TemplateDrilling Running",
    "TemplateDrilling Ready",
    "RelativeCartesianLinearMove Running",
    "RelativeCartesianLinearMove Ready",
    "DrillHole Ready",
]
JOINTS = ["Base", "Shoulder", "Elbow", "Wrist1", "Wrist2", "Wrist3"]

logging.basicConfig(level=logging.ERROR)


def nid(x) -> ua.NodeId:
    return ua.NodeId(x.Identifier, x.NamespaceIndex)


async def children(client: Client, node_id: ua.NodeId) -> dict:
    """Forward hierarchical children by BrowseName (name part)."""
    refs = await client.get_node(node_id).get_references(
        refs=HIERARCHICAL, direction=ua.BrowseDirection.Forward, includesubtypes=True
    )
    return {r.BrowseName.Name: nid(r.NodeId) for r in refs if r.ReferenceTypeId != HAS_SUBTYPE}


async def find(client: Client, path: list) -> ua.NodeId:
    node = client.nodes.objects.nodeid
    for i, name in enumerate(path):
        kids = await children(client, node)
        if name not in kids:
            raise LookupError(f"{'/'.join(path[:i]) or 'Objects'} has no child {name} (it has {sorted(kids)})")
        node = kids[name]
    return node


async def derives_from_program(client: Client, node_id: ua.NodeId) -> bool:
    refs = await client.get_node(node_id).get_references(refs=HAS_TYPE_DEFINITION, direction=ua.BrowseDirection.Forward)
    if not refs:
        return False
    t = nid(refs[0].NodeId)
    for _ in range(16):
        if t == PROGRAM_STATE_MACHINE_TYPE:
            return True
        up = await client.get_node(t).get_references(refs=HAS_SUBTYPE, direction=ua.BrowseDirection.Inverse)
        if not up:
            return False
        t = nid(up[0].NodeId)
    return False


class Skill:
    """A skill on one server: its nodes, and what a subscription saw of it."""

    def __init__(self, client: Client, server: str, name: str, node: ua.NodeId, kids: dict) -> None:
        self.client, self.server, self.name, self.node, self.kids = client, server, name, node, kids
        self.states: list = []  # CurrentState values, in order
        self.events: list = []  # (Time, ToState, Transition, SkillName)

    async def inputs(self, values: dict) -> None:
        params = await children(self.client, self.kids["InputParameterSet"])
        for name, variant in values.items():
            await self.client.get_node(params[name]).write_value(ua.DataValue(variant))

    async def output(self, name: str):
        params = await children(self.client, self.kids["OutputParameterSet"])
        return await self.client.get_node(params[name]).read_value()

    async def call(self, method: str) -> ua.StatusCode:
        try:
            await self.client.get_node(self.node).call_method(self.kids[method])
            return ua.StatusCode(ua.StatusCodes.Good)
        except ua.UaStatusCodeError as e:
            return ua.StatusCode(e.code)

    def state(self) -> str:
        return self.states[-1] if self.states else ""

    async def wait_state(self, state: str, timeout: float = 15.0) -> bool:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.state() == state:
                return True
            await asyncio.sleep(0.01)
        return False

    async def wait_event(self, to_state: str, count: int = 1, timeout: float = 15.0) -> bool:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if sum(1 for e in self.events if e[1] == to_state) >= count:
                return True
            await asyncio.sleep(0.01)
        return False

    def clear(self) -> None:
        self.events.clear()
        self.states[:] = self.states[-1:]


class Handler:
    def __init__(self) -> None:
        self.by_state_node: dict = {}
        self.by_skill_node: dict = {}

    def datachange_notification(self, node, val, data):
        skill = self.by_state_node.get(node.nodeid)
        if skill is not None:
            skill.states.append(val.Text if isinstance(val, ua.LocalizedText) else str(val))

    def event_notification(self, event):
        fields = event.get_event_props_as_fields_dict()
        source = fields.get("SourceNode")
        skill = self.by_skill_node.get(source.Value if source is not None else None)
        if skill is None:
            return
        text = lambda k: getattr(getattr(fields.get(k), "Value", None), "Text", None)
        name = getattr(fields.get("SkillName"), "Value", None)
        skill.events.append((fields["Time"].Value, text("ToState"), text("Transition"), name))

    def status_change_notification(self, status):
        pass


async def skill_events(client: Client):
    """SkillTransitionEventType (found by browsing) and an event filter for it: the type's select clauses and
    an OfType where clause. async-opcua 0.19 compares only numbers and Booleans in InList, so the
    `EventType InList [...]` that asyncua writes by default matches no event of an async-opcua server."""
    ns = await client.get_namespace_index(COMMON_SKILLS)
    event_type = await client.nodes.base_event_type.get_child(
        ["0:TransitionEventType", "0:ProgramTransitionEventType", f"{ns}:SkillTransitionEventType"]
    )
    evfilter = await get_filter_from_event_type([event_type])
    of_type = ua.ContentFilterElement(
        FilterOperator=ua.FilterOperator.OfType, FilterOperands=[ua.LiteralOperand(Value=ua.Variant(event_type.nodeid))]
    )
    evfilter.WhereClause = ua.ContentFilter(Elements=[of_type])
    return event_type, evfilter


async def watch(client: Client, server: str, skills_path: list, names: list) -> dict:
    """Subscribes to CurrentState and the transition events of the skills `names` of a SkillSet."""
    handler = Handler()
    sub = await client.create_subscription(20, handler)
    event_type, evfilter = await skill_events(client)
    skill_set = await find(client, skills_path)
    out = {}
    for name in names:
        node = (await children(client, skill_set))[name]
        kids = await children(client, node)
        skill = Skill(client, server, name, node, kids)
        handler.by_state_node[kids["CurrentState"]] = skill
        handler.by_skill_node[node] = skill
        await sub.subscribe_data_change(client.get_node(kids["CurrentState"]), queuesize=20, sampling_interval=0)
        await sub.subscribe_events(client.get_node(node), event_type, evfilter=evfilter, queuesize=100)
        out[name] = skill
    for skill in out.values():
        await skill.wait_state("Ready", 5.0)
    return out


def doubles(*xs) -> ua.Variant:
    return ua.Variant(list(xs), ua.VariantType.Double)


def double(x) -> ua.Variant:
    return ua.Variant(float(x), ua.VariantType.Double)


async def skill_sets(report: Report, robot: Client, unit: Client, cell: Client) -> None:
    expected = [
        ("robot", robot, ROBOT_SKILLS, {"AbsoluteJointPTPMove", "RelativeCartesianLinearMove", "AbsoluteCartesianLinearMove"}),
        ("drilling unit", unit, UNIT_SKILLS, {"TemplateDrilling"}),
        ("cell", cell, CELL_SKILLS, {"DrillHole", "ReferenceDrillBush"}),
        ("robot", robot, SYSTEM + ["SkillSet"], set()),
    ]
    for server, client, path, names in expected:
        kids = await children(client, await find(client, path))
        report.check(f"{server}: {'/'.join(path)} lists {sorted(names)}", set(kids) == names, f"found {sorted(kids)}")
        for name in sorted(names):
            report.check(f"{server}: {name} is a ProgramStateMachineType", await derives_from_program(client, kids[name]))


async def basic_skill(report: Report, robot: Client) -> None:
    skills = await watch(robot, "robot", ROBOT_SKILLS, ["AbsoluteJointPTPMove"])
    ptp = skills["AbsoluteJointPTPMove"]
    report.check("PTP: CurrentState is Ready at first", ptp.state() == "Ready", f"{ptp.states}")
    target = [10.0, -20.0, 30.0, -40.0, 50.0, -60.0]
    await ptp.inputs({"Speed": double(30), "Acceleration": double(100), "TargetJointPositions": doubles(*target)})
    ptp.clear()
    status = await ptp.call("Start")
    report.check("PTP: Start with input parameters is Good", status.is_good(), f"{status}")
    report.check("PTP: Running, then Ready", await ptp.wait_event("Ready"), f"events {ptp.events}")
    await asyncio.sleep(0.2)
    report.check("PTP: CurrentState went Ready -> Running -> Ready", ptp.states == ["Ready", "Running", "Ready"], f"{ptp.states}")
    transitions = [(e[1], e[2], e[3]) for e in ptp.events]
    report.check(
        "PTP: two transition events (ReadyToRunning, RunningToReady) with SkillName",
        transitions == [("Running", "ReadyToRunning", "AbsoluteJointPTPMove"), ("Ready", "RunningToReady", "AbsoluteJointPTPMove")],
        f"{transitions}",
    )
    result = await ptp.output("Result")
    report.check("PTP: Result is Good", isinstance(result, ua.StatusCode) and result.is_good(), f"{result}")
    axes = await find(robot, SYSTEM + ["MotionDeviceSystem", "MotionDevices", "Manipulator", "Axes"])
    positions = []
    for joint in JOINTS:
        params = await children(robot, (await children(robot, axes))[joint])
        value = await robot.get_node((await children(robot, params["ParameterSet"]))["ActualPosition"]).read_value()
        positions.append(value)
    report.check("PTP: the joints are at the target", all(abs(p - t) < 1e-9 for p, t in zip(positions, target)), f"{positions}")

    # Halt while Running, Start while Halted, Reset.
    await ptp.inputs({"TargetJointPositions": doubles(0, 0, 0, 0, 0, 0)})
    ptp.clear()
    await ptp.call("Start")
    report.check("PTP: Running again", await ptp.wait_state("Running"), f"{ptp.states}")
    status = await ptp.call("Halt")
    report.check("PTP: Halt while Running is Good", status.is_good(), f"{status}")
    report.check("PTP: Halted", await ptp.wait_state("Halted"), f"{ptp.states}")
    result = await ptp.output("Result")
    report.check("PTP: Result says a client halted it", result == ua.StatusCode(ua.StatusCodes.BadRequestCancelledByClient), f"{result}")
    status = await ptp.call("Start")
    report.check("PTP: Start while Halted is BadInvalidState", status == ua.StatusCode(ua.StatusCodes.BadInvalidState), f"{status}")
    status = await ptp.call("Reset")
    report.check("PTP: Reset is Good", status.is_good(), f"{status}")
    report.check("PTP: Ready after Reset", await ptp.wait_state("Ready"), f"{ptp.states}")
    await asyncio.sleep(0.2)
    transitions = [e[2] for e in ptp.events]
    report.check(
        "PTP: events ReadyToRunning, RunningToHalted, HaltedToReady",
        transitions == ["ReadyToRunning", "RunningToHalted", "HaltedToReady"],
        f"{transitions}",
    )


async def composite_skill(report: Report, robot: Client, unit: Client, cell: Client) -> None:
    mv = (await watch(robot, "robot", ROBOT_SKILLS, ["RelativeCartesianLinearMove"]))["RelativeCartesianLinearMove"]
    drill = (await watch(unit, "drilling unit", UNIT_SKILLS, ["TemplateDrilling"]))["TemplateDrilling"]
    hole = (await watch(cell, "cell", CELL_SKILLS, ["DrillHole"]))["DrillHole"]
    inputs = {
        "InsertionDistance": double(12.5),
        "HoleDiameter": double(6),
        "Depth": double(8),
        "FeedRate": double(120),
        "SpindleSpeed": double(3000),
        "ClampForce": double(400),
    }
    await hole.inputs(inputs)

    # 1. A whole run: move in, drill, move out, on the other servers, within DrillHole's Running.
    status = await hole.call("Start")
    report.check("DrillHole: Start is Good", status.is_good(), f"{status}")
    report.check("DrillHole: back in Ready", await hole.wait_event("Ready", timeout=30), f"{hole.events}")
    await asyncio.sleep(0.3)
    steps = sorted(
        [(e[0], f"{s.name} {e[1]}") for s in (mv, drill, hole) for e in s.events], key=lambda x: x[0]
    )
    order = [s for _, s in steps]
    report.check(
        "DrillHole: runs move, drill, move in this order",
        order == DRILL_HOLE_EVENTS,
        f"{order}",
    )
    report.check("DrillHole: CurrentState Ready -> Running -> Ready", hole.states == ["Ready", "Running", "Ready"], f"{hole.states}")

    # 2. The drilling unit's skill is halted while DrillHole runs: DrillHole halts with the same cause.
    for s in (mv, drill, hole):
        s.clear()
    await hole.call("Start")
    report.check("DrillHole: TemplateDrilling runs", await drill.wait_state("Running"), f"{drill.states}")
    status = await drill.call("Halt")
    report.check("TemplateDrilling: Halt (by a client of the drilling unit) is Good", status.is_good(), f"{status}")
    report.check("DrillHole: Halted because TemplateDrilling halted", await hole.wait_state("Halted"), f"{hole.states}")
    cause = await hole.output("Result")
    report.check("DrillHole: Result is TemplateDrilling's cause", cause == ua.StatusCode(ua.StatusCodes.BadRequestCancelledByClient), f"{cause}")
    await asyncio.sleep(0.3)
    moves = sum(1 for e in mv.events if e[1] == "Running")
    report.check("DrillHole: did not move out after the halted drilling", moves == 1, f"{mv.events}")
    status = await hole.call("Start")
    report.check("DrillHole: Start while Halted is BadInvalidState", status == ua.StatusCode(ua.StatusCodes.BadInvalidState), f"{status}")
    for s in (hole, drill):
        status = await s.call("Reset")
        report.check(f"{s.name}: Reset is Good", status.is_good(), f"{status}")
        report.check(f"{s.name}: Ready after Reset", await s.wait_state("Ready"), f"{s.states}")

    # 3. DrillHole is halted while it drills: the drilling is halted too.
    await hole.call("Start")
    report.check("DrillHole: TemplateDrilling runs again", await drill.wait_state("Running"), f"{drill.states}")
    status = await hole.call("Halt")
    report.check("DrillHole: Halt is Good", status.is_good(), f"{status}")
    report.check("TemplateDrilling: halted with DrillHole", await drill.wait_state("Halted"), f"{drill.states}")
    for s in (hole, drill):
        await s.call("Reset")
        report.check(f"{s.name}: Ready again", await s.wait_state("Ready"), f"{s.states}")


async def run(robot_url: str, unit_url: str, cell_url: str) -> Report:
    report = Report()
    clients = [Client(url=u, timeout=10) for u in (robot_url, unit_url, cell_url)]
    for c in clients:
        await c.connect()
    robot, unit, cell = clients
    try:
        for step in (
            lambda: skill_sets(report, robot, unit, cell),
            lambda: basic_skill(report, robot),
            lambda: composite_skill(report, robot, unit, cell),
        ):
            try:
                await step()
            except Exception:  # a failure of one part is reported; the others still run
                report.check("no exception", False, traceback.format_exc(limit=3).replace("\n", " | "))
    finally:
        for c in clients:
            await c.disconnect()
    return report


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--robot", required=True)
    parser.add_argument("--unit", required=True)
    parser.add_argument("--cell", required=True)
    args = parser.parse_args()
    try:
        report = asyncio.run(run(args.robot, args.unit, args.cell))
    except Exception:
        traceback.print_exc()
        print("0 passed, 1 failed")
        return 1
    print(f"{report.passed} passed, {report.failed} failed")
    return 0 if report.failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
