within RoboticsExample;
model TwoAxes "The Axes folder of a motion device, holding two first-order axes"
  extends OpcUaRobotics.Declarations.MotionDeviceType_Axes(
    nAxisIdentifier=2,
    redeclare model AxisIdentifier = FirstOrderAxis,
    axisIdentifier(T={0.1, 0.3}, target={1, -0.5}));
end TwoAxes;
