within Planted;
model RedeclaredOverride "Plugs in SubModified and repeats its choice of C (valid)"
  extends Planted.Holder(redeclare model M = Planted.SubModified, m(redeclare model C = Planted.Outer));
end RedeclaredOverride;
