within BindingExample;
model LoopbackCell "The bound drilling cell, its reads fed by tables"
  inner parameter OpcUaSupport.Interfaces.Connection connection(endpointUrl="opc.tcp://localhost:4840")
    "The server the blocks would talk to; the loopback blocks do not";
  NodesetCompilerDrillingProcess.Instances.Bindings.DrillingCell cell(
    readSkillSetReferenceDrillBushInputParameterSetApproachDistance(table=[0, 10; 1, 30]),
    readSkillSetDrillHoleInputParameterSetDepth(table=[0, 5; 2, 5; 2, 8]),
    skillSet(drillHole(outputParameterSet(result=if time < 1 then 0 else -2136276992)))) "The drilling cell";
  Integer result = cell.writeSkillSetDrillHoleOutputParameterSetResult.written
    "The Result DrillHole publishes, as written: Good, then Bad_Timeout (0x80AB0000) from 1 s on";
  annotation (
    experiment(StopTime=3, Interval=0.01),
    Documentation(info="<html><p>ApproachDistance is read in millimetres (OPC UA) and used in metres (Modelica):
0.01 m at the start, 0.02 m at 0.5 s, 0.03 m from 1 s on. The test reads the instance's variables from the
simulation result rather than through variables of this model: rumoca 0.10.2 resolves
<code>cell.skillSet.referenceDrillBush.inputParameterSet</code> to the class DrillHole's InputParameterSet has
when a name reaches into it (the leak <code>tests/modelica/RumocaBehaviour</code> shows).</p></html>"));
end LoopbackCell;
