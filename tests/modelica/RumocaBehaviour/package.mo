within;
package RumocaBehaviour "Minimal reproductions of how rumoca 0.10.2 reads redeclarations and String variables, which the generator and the tests work around"
  annotation (Documentation(info="<html>
<p>Hand-written, not generated. Each <code>*Demo</code> model is simulated by the test
<code>rumoca_behaviour_is_as_reproduced</code> in <code>tests/tests/modelica.rs</code>, which asserts what rumoca
does today, so that a rumoca release that changes it shows up as a failing test (and the workaround in the
generator can then be reconsidered).</p>
<ul>
<li><code>LeakDemo</code>: <code>Robot</code> and <code>Axis</code> both extend <code>Base</code> and redeclare its
replaceable class <code>PS</code>. The axis <code>r.a</code> nested in the robot gets the robot's <code>PS</code>
(<code>OuterPS</code>) instead of its own (<code>InnerPS</code>): <code>r.a.ps.pos</code> and the
<code>connect</code> to it vanish without a diagnostic. By the Modelica specification (7.3) the axis keeps
<code>InnerPS</code>.</li>
<li><code>PinnedDemo</code>: the same, but the component repeats its class's choice,
<code>MyAxis a(redeclare model PS = InnerPS)</code>, which is equivalent Modelica; rumoca then reads it right.
This is what the generator does (<code>Mod::Pin</code> in <code>nodeset-compiler/src/emit/modelica</code>).</li>
<li><code>DroppedDemo</code>: the other construct one would use, a replaceable component
(<code>replaceable Empty ps</code> in <code>CBase</code>) redeclared two <code>extends</code> levels below its
declaration (<code>CAxis extends CMid(redeclare InnerPS ps)</code>): rumoca drops the component and the
<code>connect</code> to it, again without a diagnostic.</li>
<li><code>StringDemo</code>: a String variable (not a parameter). rumoca checks the model but refuses to
simulate it (<code>String values are not numeric Solve coordinates</code>). Every OPC UA state machine has
one (CurrentState), so <code>tests/modelica/simulate.py --strings-as-parameters</code> simulates a copy of the
library in which String variables are parameters and their equations are left out.</li>
</ul>
</html>"));
end RumocaBehaviour;
