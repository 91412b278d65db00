within OpcUaSupport.Loopback;
block ReadReal "Reads Real values from a table instead of a server"
  extends OpcUaSupport.Interfaces.ReadReal;
  parameter Real table[:, 2] = [0, initValue] "Rows of time (s) and OPC UA value; linear between rows, held before the first and after the last";
equation
  value = interpolate(table, time);
protected
  function interpolate "Linear interpolation in a table of times and values"
    input Real table[:, 2] "Rows of time and value, times ascending";
    input Real t "Time";
    output Real y "Value at t: linear between rows, held before the first and after the last";
  algorithm
    y := table[1, 2];
    for i in 1:size(table, 1) - 1 loop
      if t >= table[i + 1, 1] then
        y := table[i + 1, 2];
      elseif t > table[i, 1] then
        y := table[i, 2] + (table[i + 1, 2] - table[i, 2])*(t - table[i, 1])/(table[i + 1, 1] - table[i, 1]);
      end if;
    end for;
  end interpolate;
  annotation ({BLOCK_ICON}, Documentation(info="<html><p>A read from a table instead of a server: <code>value</code> follows <code>table</code> over time, linear between its rows. It stands in for a server in simulations and tests of bound models.</p></html>"));
end ReadReal;
