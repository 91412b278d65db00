within Planted;
model Outer "Has one component, inn"
  extends Planted.Empty;
  Planted.Inner inn;
end Outer;
