within RumocaBehaviour;
model ArrayLeakDemo "The robot's redeclaration of PS leaks into an array of axes too"
  ArrayRobot r "The robot";
  annotation (experiment(StopTime=1, Interval=0.1));
end ArrayLeakDemo;
