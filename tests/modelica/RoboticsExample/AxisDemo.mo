within RoboticsExample;
model AxisDemo "One axis moving to 1 rad"
  FirstOrderAxis axis(T=0.2, target=1) "The axis";
  annotation (experiment(StopTime=2, Interval=0.01));
end AxisDemo;
