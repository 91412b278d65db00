within RoboticsExample;
model FirstOrderAxis "A robot axis whose position follows its target with a first-order lag"
  extends OpcUaRobotics.ObjectTypes.AxisType(
    motionProfile=OpcUaRobotics.Types.AxisMotionProfileEnumeration.ROTARY,
    parameterSet(
      actualPosition=position,
      use_actualSpeed=true,
      actualSpeed=der(position)));
  parameter Real T(unit="s") = 0.2 "Time constant of the position loop";
  parameter Real target(unit="rad") = 1 "Target position";
  Real position(unit="rad", start=0, fixed=true) "Position of the axis";
equation
  der(position) = (target - position)/T;
  annotation (Documentation(info="<html><p>The generated <code>AxisType</code> declares ActualPosition and
ActualSpeed as outputs of its ParameterSet; this model computes them from <code>der(position) =
(target - position)/T</code>.</p></html>"));
end FirstOrderAxis;
