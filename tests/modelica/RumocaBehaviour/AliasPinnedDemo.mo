within RumocaBehaviour;
model AliasPinnedDemo "With the choice repeated in the alias's definition, the leak remains"
  AliasPinnedRobot r "The robot";
  annotation (experiment(StopTime=1, Interval=0.1));
end AliasPinnedDemo;
