"""Second opinion on our skill nodesets: python asyncua's XML importer loads them into a server.

usage: .venv/bin/python tests/interop/skills_import.py --vendor nodesets/vendor --nodesets nodesets

The server (not started, no network) has asyncua's own ns0; DI, IA and Robotics are imported from the
pinned files with ``strict_mode=False``, because asyncua cannot place the DesignToolOnly objects of DI
1.05.0 and logs their failures. Our three files are imported with ``strict_mode=True``, and any warning
asyncua logs while it imports them is a failure (it warns, for example, about nodes with two parents or
references to missing nodes). Then a few facts are read back through the server's node API.

Every check prints PASS or FAIL; the last line is ``N passed, N failed``; the exit status is 1 if any
check failed.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys
from pathlib import Path

from asyncua import Server, ua

from report import Report

CS = "http://nodeset-compiler.dev/CommonSkills/"
RC = "http://nodeset-compiler.dev/RobotCell/"
DP = "http://nodeset-compiler.dev/DrillingProcess/"
DI = "http://opcfoundation.org/UA/DI/"
ROBOTICS = "http://opcfoundation.org/UA/Robotics/"
VENDOR = ["Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.IA.NodeSet2.xml", "Opc.Ua.Robotics.NodeSet2.xml"]
OURS = ["CommonSkills.NodeSet2.xml", "RobotCell.NodeSet2.xml", "DrillingProcess.NodeSet2.xml"]


class Collect(logging.Handler):
    """Keeps the warnings and errors asyncua logs."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


async def child(node, path: list[tuple[str, str]], idx: dict[str, int]):
    return await node.get_child([f"{idx[uri]}:{name}" for uri, name in path])


async def names(nodes) -> list[str]:
    return sorted([(await n.read_browse_name()).Name for n in nodes])


async def main(vendor: Path, ours: Path) -> int:
    report = Report()
    logging.basicConfig(level=logging.ERROR)
    server = Server()
    await server.init()
    for name in VENDOR:
        await server.import_xml(str(vendor / name), strict_mode=False)

    collect = Collect()
    logging.getLogger("asyncua").addHandler(collect)
    logging.getLogger("asyncua").setLevel(logging.WARNING)
    for name in OURS:
        collect.records.clear()
        try:
            added = await server.import_xml(str(ours / name), strict_mode=True)
        except Exception as e:  # noqa: BLE001 - any failure of the importer is the finding
            report.check(f"import {name}", False, f"{type(e).__name__}: {e}")
            continue
        warnings = [r.getMessage()[:300] for r in collect.records]
        report.check(f"import {name} ({len(added)} nodes)", not warnings, "; ".join(warnings[:5]))
    logging.getLogger("asyncua").removeHandler(collect)
    if report.failed:
        print(f"{report.passed} passed, {report.failed} failed")
        return 1

    uris = await server.get_namespace_array()
    idx = {u: uris.index(u) for u in (CS, RC, DP, DI, ROBOTICS)}
    idx["ns0"] = 0

    # The controller of the UR10e in the instance offers the three move skills.
    device_set = await server.nodes.objects.get_child(f"{idx[DI]}:DeviceSet")
    system = await child(device_set, [(DP, "TemplateDrillingLwrSystem")], idx)
    skill_set = await child(system, [(RC, "MotionDeviceSystem"), (ROBOTICS, "Controllers"), (RC, "URController"),
                                     (CS, "SkillSet")], idx)
    skills = await names(await skill_set.get_children())
    report.check("URController/SkillSet holds the three move skills",
                 skills == ["AbsoluteCartesianLinearMove", "AbsoluteJointPTPMove", "RelativeCartesianLinearMove"],
                 str(skills))

    # A skill instance is a ready program with its inputs in InputParameterSet.
    ptp = await child(skill_set, [(RC, "AbsoluteJointPTPMove")], idx)
    state = await (await ptp.get_child("0:CurrentState")).read_value()
    report.check("AbsoluteJointPTPMove is Ready", state.Text == "Ready", repr(state))
    target = await child(ptp, [(CS, "InputParameterSet"), (CS, "TargetJointPositions")], idx)
    eu = await (await target.get_child("0:EngineeringUnits")).read_value()
    report.check("TargetJointPositions is in degrees", getattr(eu, "UnitId", None) == 17476, repr(eu))
    report.check("TargetJointPositions is writable",
                 (await target.read_attribute(ua.AttributeIds.AccessLevel)).Value.Value == 3)
    report.check("TargetJointPositions has six elements",
                 (await target.read_attribute(ua.AttributeIds.ArrayDimensions)).Value.Value == [6])

    # The composite skills of the cell, with the Suspend and Resume of CompositeSkillType.
    cell = await server.nodes.objects.get_child(f"{idx[DP]}:DrillingCell")
    drill = await child(cell, [(CS, "SkillSet"), (DP, "DrillHole")], idx)
    methods = await names(await drill.get_methods())
    report.check("DrillHole has Start, Suspend, Resume, Halt, Reset",
                 methods == ["Halt", "Reset", "Resume", "Start", "Suspend"], str(methods))
    pose = await child(cell, [(CS, "SkillSet"), (DP, "ReferenceDrillBush"), (CS, "InputParameterSet"),
                              (DP, "HolePosition")], idx)
    report.check("HolePosition is a 3DFrame",
                 (await pose.read_data_type()) == ua.NodeId(18814, 0), str(await pose.read_data_type()))

    # The enumeration of GrippingSkillType, as load_data_type_definitions builds it.
    await server.load_data_type_definitions()
    enum = getattr(ua, "GripperActionEnumeration", None)
    report.check("GripperActionEnumeration is loaded",
                 enum is not None and enum.Open == 0 and enum.Close == 1, repr(enum))

    print(f"{report.passed} passed, {report.failed} failed")
    return 1 if report.failed else 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vendor", type=Path, required=True, help="folder of the pinned DI, IA and Robotics files")
    parser.add_argument("--nodesets", type=Path, required=True, help="folder of our three skill nodesets")
    args = parser.parse_args()
    sys.exit(asyncio.run(main(args.vendor, args.nodesets)))
