within SkillExample;
model DrillHoleRun "DrillHole through Start, Halt, a Start that Halted ignores, Reset and Start again"
  NodesetCompilerDrillingProcess.Instances.DrillingCell cell(
    skillSet(drillHole(
      start=time >= 1 and time < 1.2 or time >= 2.5 and time < 2.7 or time >= 4 and time < 4.2,
      halt=time >= 2 and time < 2.2,
      reset=time >= 3 and time < 3.2))) "The drilling cell; its DrillHole skill starts in Ready";
  Integer state = cell.skillSet.drillHole.currentStateNumber "The number of the state DrillHole is in";
  annotation (experiment(StopTime=5, Interval=0.01));
end DrillHoleRun;
