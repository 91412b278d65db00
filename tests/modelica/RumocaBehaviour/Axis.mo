within RumocaBehaviour;
model Axis "Chooses InnerPS"
  extends Base(redeclare model PS = InnerPS);
end Axis;
