within RoboticsExample;
model RobotDemo "A two-axis motion device moving both axes to their targets"
  TwoAxisRobot robot "The motion device";
  annotation (experiment(StopTime=2, Interval=0.01));
end RobotDemo;
