within RoboticsExample;
model TwoAxes "The Axes folder of a motion device, holding two driven axes"
  extends OpcUaRobotics.Declarations.MotionDeviceType_Axes(
    nAxisIdentifier=2,
    axisIdentifierBrowseNames={"Axis1", "Axis2"},
    redeclare model AxisIdentifier = DrivenAxis,
    axisIdentifier(T={0.1, 0.3}, target={1, -0.5}));
  annotation (Documentation(info="<html><p>The placeholder <code>&lt;AxisIdentifier&gt;</code> with two elements,
its replaceable class redeclared to <code>DrivenAxis</code> and the elements named as a server would name them.</p></html>"));
end TwoAxes;
