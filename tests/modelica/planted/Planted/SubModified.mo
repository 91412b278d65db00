within Planted;
model SubModified "Modifies c.inn, which exists since C is Outer"
  extends Planted.Sub(c(inn(v=2)));
end SubModified;
