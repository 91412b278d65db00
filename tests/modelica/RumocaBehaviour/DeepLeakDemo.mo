within RumocaBehaviour;
model DeepLeakDemo "The robot's redeclaration of PS leaks into an axis two levels in"
  DeepRobot r "The robot";
  annotation (experiment(StopTime=1, Interval=0.1));
end DeepLeakDemo;
