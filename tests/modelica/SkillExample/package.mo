within;
package SkillExample "A skill of the drilling cell driven through its state machine by time events"
  annotation (
    version="1.0.0",
    uses(NodesetCompilerDrillingProcess(version="1.0.0"), OpcUaSupport(version="0.1.0")),
    Documentation(info="<html>
<p>A hand-written user model, not generated. <code>DrillHoleRun</code> takes the generated instance
<code>NodesetCompilerDrillingProcess.Instances.DrillingCell</code> and drives the trigger inputs of its DrillHole
skill (a ProgramStateMachineType) with pulses: a rising edge of <code>start</code>, <code>halt</code> or
<code>reset</code> stands for a call of the method of that name.</p>
<p>The test <code>tests/tests/modelica.rs</code> simulates it with rumoca and checks the state numbers
(Halted 11, Ready 12, Running 13) at chosen times. rumoca 0.10.2 cannot simulate String variables, so the
test simulates with <code>tests/modelica/simulate.py --strings-as-parameters</code>; that the state text
follows the number is checked on the generated code (a <code>final</code> binding to the text the state
machine's equation sets).</p>
</html>"));
end SkillExample;
