// A node-opcua server for tests/tests/verify.rs: ns0, DI, IA and Robotics from
// node-opcua-nodesets, one correct MotionDeviceSystem instance (`GoodSystem`) and one with three planted
// defects (`BadSystem`):
//   1. its motion device has no `SerialNumber` (a Mandatory property of DI's ComponentType, NS0401);
//   2. its motion device's `Model` (a LocalizedText) holds a Double (NS0406);
//   3. its `MotionDevices` folder holds, beside a correct motion device, a `ControllerType` object in the
//      place of the placeholder `<MotionDeviceIdentifier>` (NS0407).
// Usage: node server.js PORT. Prints `listening on <url>` when ready; stops on SIGTERM.
"use strict";
const path = require("path");
const { OPCUAServer, DataType, Variant } = require("node-opcua");

const port = parseInt(process.argv[2], 10);
if (!(port > 0)) {
    console.error("usage: node server.js PORT");
    process.exit(2);
}
const dir = path.join(path.dirname(require.resolve("node-opcua-nodesets/package.json")), "nodesets");
const files = ["Opc.Ua.NodeSet2.xml", "Opc.Ua.Di.NodeSet2.xml", "Opc.Ua.IA.NodeSet2.xml", "Opc.Ua.Robotics.NodeSet2.xml"];

function placeholders(space, ns) {
    return {
        motionDevice: space.findObjectType("MotionDeviceType", ns.robotics),
        controller: space.findObjectType("ControllerType", ns.robotics),
        safetyState: space.findObjectType("SafetyStateType", ns.robotics),
        powerTrain: space.findObjectType("PowerTrainType", ns.robotics),
        motor: space.findObjectType("MotorType", ns.robotics),
        axis: space.findObjectType("AxisType", ns.robotics),
        software: space.findObjectType("SoftwareType", ns.di),
        taskControl: space.findObjectType("TaskControlType", ns.robotics),
    };
}

function child(node, name) {
    const found = node.getChildByName(name);
    if (!found) throw new Error(`${node.browseName.toString()} has no child ${name}`);
    return found;
}

/// A MotionDeviceSystem with one motion device (with one power train driving one axis), one controller and
/// one safety state: the mandatory placeholders filled.
function system(space, ns, own, name, deviceSet) {
    const t = placeholders(space, ns);
    const sys = space.findObjectType("MotionDeviceSystemType", ns.robotics).instantiate({ browseName: name, organizedBy: deviceSet });
    const device = t.motionDevice.instantiate({ browseName: { namespaceIndex: own, name: "Robot" }, componentOf: child(sys, "MotionDevices") });
    const powerTrain = t.powerTrain.instantiate({ browseName: { namespaceIndex: own, name: "PowerTrain1" }, componentOf: child(device, "PowerTrains") });
    t.motor.instantiate({ browseName: { namespaceIndex: own, name: "Motor1" }, componentOf: powerTrain });
    t.axis.instantiate({ browseName: { namespaceIndex: own, name: "Axis1" }, componentOf: child(device, "Axes") });
    controller(space, ns, own, "Controller", child(sys, "Controllers"));
    t.safetyState.instantiate({ browseName: { namespaceIndex: own, name: "SafetyState" }, componentOf: child(sys, "SafetyStates") });
    return { sys, device };
}

/// A controller with its mandatory placeholders filled: one software and one task control.
function controller(space, ns, own, name, parent) {
    const t = placeholders(space, ns);
    const c = t.controller.instantiate({ browseName: { namespaceIndex: own, name }, componentOf: parent });
    t.software.instantiate({ browseName: { namespaceIndex: own, name: "Software1" }, componentOf: child(c, "Software") });
    t.taskControl.instantiate({ browseName: { namespaceIndex: own, name: "TaskControl1" }, componentOf: child(c, "TaskControls") });
    return c;
}

async function main() {
    const server = new OPCUAServer({ port, nodeset_filename: files.map((f) => path.join(dir, f)), allowAnonymous: true });
    await server.initialize();
    const space = server.engine.addressSpace;
    const ns = { di: space.getNamespaceIndex("http://opcfoundation.org/UA/DI/"), robotics: space.getNamespaceIndex("http://opcfoundation.org/UA/Robotics/") };
    const own = space.getOwnNamespace().index;
    const deviceSet = space.rootFolder.objects.getFolderElementByName("DeviceSet");
    if (!deviceSet) throw new Error("DI's DeviceSet is missing");
    system(space, ns, own, "GoodSystem", deviceSet);
    const bad = system(space, ns, own, "BadSystem", deviceSet);
    // 1. A missing mandatory member.
    space.deleteNode(child(bad.device, "SerialNumber"));
    // 2. A value of the wrong type: a Double where the DataType is LocalizedText (bound to a getter:
    // node-opcua refuses to store it with setValueFromSource).
    const model = child(bad.device, "Model");
    model.bindVariable({ get: () => new Variant({ dataType: DataType.Double, value: 42.5 }) }, true);
    // 3. An object of the wrong type in a placeholder's place.
    controller(space, ns, own, "NotAMotionDevice", child(bad.sys, "MotionDevices"));
    await server.start();
    console.log(`listening on opc.tcp://127.0.0.1:${port}/UA/NodeOPCUA`);
    const stop = async () => {
        await server.shutdown(0);
        process.exit(0);
    };
    process.on("SIGTERM", stop);
    process.on("SIGINT", stop);
}

main().catch((e) => {
    console.error(e);
    process.exit(1);
});
