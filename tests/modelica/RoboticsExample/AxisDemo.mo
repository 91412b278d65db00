within RoboticsExample;
model AxisDemo "One axis moving to 1 rad"
  DrivenAxis axis(T=0.2, target=1) "The axis";
  annotation (experiment(StopTime=2, Interval=0.01), Documentation(info="<html><p>One
<code>DrivenAxis</code>: its ParameterSet/ActualPosition reaches <code>1 - exp(-1)</code> at <code>t = T</code>.</p></html>"));
end AxisDemo;
