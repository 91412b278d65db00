within RumocaBehaviour;
model ViaDemo "With the choice repeated through an alias of the robot, the axes keep InnerPS"
  ViaRobot r "The robot";
  annotation (experiment(StopTime=1, Interval=0.1));
end ViaDemo;
