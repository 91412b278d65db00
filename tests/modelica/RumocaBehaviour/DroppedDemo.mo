within RumocaBehaviour;
model DroppedDemo "The redeclared component ps is dropped"
  CAxis a "The axis";
  annotation (experiment(StopTime=1, Interval=0.1));
end DroppedDemo;
