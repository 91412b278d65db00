within RoboticsExample;
model TwoAxisRobot "A motion device with two first-order axes"
  extends OpcUaRobotics.ObjectTypes.MotionDeviceType(
    manufacturer="DLR",
    model_="Two-axis demonstrator",
    productCode="TA-2",
    serialNumber="0001",
    motionDeviceCategory=OpcUaRobotics.Types.MotionDeviceCategoryEnumeration.CARTESIANROBOT,
    redeclare model Axes = TwoAxes);
end TwoAxisRobot;
