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
<li><code>ArrayLeakDemo</code>, <code>DeepLeakDemo</code>: the leak reaches an array of axes
(<code>MyAxis a[1]</code>: <code>r.a[1].ps.speed</code>) and an axis two levels in, held by a class with no
<code>PS</code> of its own (<code>r.m.a.ps.speed</code>). So every object component repeats the choices, not only
scalar ones, and not only where the enclosing class declares the alias.</li>
<li><code>AliasPinnedDemo</code>: repeating the choice in the definition of the axes' class alias
(<code>replaceable model A = MyAxis(redeclare model PS = InnerPS)</code>) does not stop the leak.</li>
<li><code>ViaDemo</code>: repeating it through an alias of the robot (<code>replaceable model A_PS = InnerPS;
A a[1](redeclare model PS = A_PS)</code>) does. The generator writes this for a component declared through a
class alias (<code>Mod::PinVia</code>), because pymoca misreads a derived class's change of the other form on an
array (<code>tests/modelica/PymocaBehaviour</code>).</li>
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
