within RoboticsExample;
model DrivenAxis "A robot axis whose ParameterSet/ActualPosition and ActualSpeed a first-order drive computes"
  extends OpcUaRobotics.ObjectTypes.AxisType(
    motionProfile=OpcUaRobotics.Types.AxisMotionProfileEnumeration.ROTARY,
    parameterSet(use_actualSpeed=true));
  parameter Real T(unit="s") = 0.2 "Time constant of the position loop";
  parameter Real target(unit="rad") = 1 "Target position";
  Constant setpoint(k=target) "The target position"
    annotation (Placement(transformation(extent={{-80,-10},{-60,10}})));
  FirstOrder drive(T=T) "The position loop of the drive"
    annotation (Placement(transformation(extent={{-40,-10},{-20,10}})));
equation
  connect(setpoint.y, drive.u);
  connect(drive.y, parameterSet.actualPosition);
  connect(drive.dy, parameterSet.actualSpeed);
  annotation (Documentation(info="<html><p>The generated <code>AxisType</code> is partial: its ParameterSet's
ActualPosition and ActualSpeed are input connectors, values the axis publishes that the physics computes. This
model connects a first-order drive to them, as one would in a diagram; <code>OpcUaRobotics.Complete.AxisType</code>
would bind them to the nodeset's values instead.</p></html>"));
end DrivenAxis;
