within RoboticsExample;
model TwoAxisRobot "A motion device with two driven axes"
  extends OpcUaRobotics.Complete.MotionDeviceType(
    manufacturer="DLR",
    model_="Two-axis demonstrator",
    productCode="TA-2",
    serialNumber="0001",
    motionDeviceCategory=OpcUaRobotics.Types.MotionDeviceCategoryEnumeration.CARTESIAN_ROBOT,
    redeclare model Axes = TwoAxes);
  annotation (Documentation(info="<html><p>The complete variant of <code>MotionDeviceType</code> (its own published
values bound to the nodeset's) with the Axes folder <code>TwoAxes</code>.</p></html>"));
end TwoAxisRobot;
