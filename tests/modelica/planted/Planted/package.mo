within;
package Planted "Small planted mistakes, one per class, that rumoca 0.10.2 lets through; the second checker and the structural checks must each reject theirs"
  annotation (Documentation(info="<html>
<p>Hand-written, not generated. <code>tests/tests/modelica.rs</code> runs each check over this package and asserts
exactly which classes it rejects (the valid classes beside the mistakes must pass), so a check that stops
catching its case fails the test.</p>
<ul>
<li><code>ModifierTypo</code>: a modifier naming a member that does not exist (rumoca catches this one).</li>
<li><code>NestedModifierTypo</code>, <code>ExtendsModifierTypo</code>: the same one level down, in a component's
and in an <code>extends</code> clause's modification (rumoca lets both through).</li>
<li><code>RecursiveA</code>, <code>RecursiveB</code>: two classes that contain each other.</li>
<li><code>ConditionalBinding</code>, <code>ConditionalEquation</code>: a binding and an equation that read a
conditional component (<code>part if usePart</code>), which Modelica 4.4.5 allows only in connections.</li>
<li><code>PinnedOverride</code>: what the generator once wrote for an instance that redeclares a replaceable
class: <code>Holder</code>'s component repeats its class's choice (<code>m(redeclare model C =
Planted.Empty)</code>), an outer modification that wins over the choice of the class the instance plugs in
(<code>Planted.SubModified</code>, whose <code>c</code> is an <code>Outer</code>), so
<code>SubModified</code>'s modifier <code>c(inn(v=2))</code> names a member the effective class lacks
(Modelica 7.2.4).</li>
<li>Valid, and must pass: <code>Inner</code>, <code>Outer</code>, <code>Part</code>, <code>Empty</code>,
<code>Base</code>, <code>Sub</code>, <code>SubModified</code>, <code>Holder</code>,
<code>ConditionalConnect</code> (a conditional connector in a connection and a modifier),
<code>RedeclaredOverride</code> (the instance also repeats the choice of the class it plugs in).</li>
</ul>
</html>"));
end Planted;
