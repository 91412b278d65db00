within RumocaBehaviour;
model PinnedDemo "With the choice repeated on the component, the axis keeps InnerPS"
  PinnedRobot r "The robot";
  annotation (experiment(StopTime=1, Interval=0.1));
end PinnedDemo;
