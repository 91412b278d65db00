within RumocaBehaviour;
model Robot "Chooses OuterPS and holds an axis"
  extends Base(redeclare model PS = OuterPS);
  MyAxis a "The axis";
end Robot;
