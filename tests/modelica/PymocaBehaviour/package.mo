within;
package PymocaBehaviour "Minimal reproduction of how pymoca 0.12.0 reads a redeclaration on an array component, which the generator works around"
  annotation (Documentation(info="<html>
<p>Hand-written, not generated. The test <code>pymoca_behaviour_is_as_reproduced</code> in
<code>tests/tests/modelica.rs</code> checks this package with <code>tests/modelica/check2.py</code> and asserts
that pymoca rejects <code>ArrayOverride</code> and nothing else, so that a pymoca release that reads it right
shows up as a failing test (and the workaround in the generator can then be reconsidered).</p>
<ul>
<li><code>ScalarOverride</code>: <code>ScalarHolder</code>'s component repeats the choice of its class's
<code>S</code> (<code>I item(redeclare model S = Empty)</code>, as the generator's pins do for rumoca). The derived
class plugs in <code>StatItem</code>, which chooses <code>Stat</code> and sets its parameter, and repeats that choice
on the component from its <code>extends</code> clause. The outer modification wins (Modelica 7.2.4): pymoca
accepts it.</li>
<li><code>ArrayOverride</code>: the same with an array of items sized by a parameter (<code>I items[n](...)</code>,
as a placeholder is). pymoca keeps the declaration's <code>S = Empty</code>, so <code>StatItem</code>'s
<code>s(giveAway = 1)</code> names a member that does not exist: a valid class rejected. (With a literal size,
<code>items[1]</code>, pymoca reads it right.)</li>
<li><code>ViaOverride</code>: what the generator writes instead (<code>Mod::PinVia</code> and
<code>Mod::Repin</code> in <code>nodeset-compiler/src/emit/modelica</code>): the declaration repeats the choice
through an alias of the enclosing class (<code>I items[n](redeclare model S = I_S)</code>), which the derived
class redeclares at class level. pymoca and rumoca both accept it.</li>
</ul>
</html>"));
end PymocaBehaviour;
