within RumocaBehaviour;
model LeakDemo "The robot's redeclaration of PS leaks into its axis"
  Robot r "The robot";
  annotation (experiment(StopTime=1, Interval=0.1));
end LeakDemo;
