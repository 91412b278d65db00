within Planted;
model ConditionalEquation "Reads a conditional component in an equation"
  parameter Boolean usePart = true;
  Planted.Part part if usePart;
  Real y;
equation
  y = 2*part.v;
end ConditionalEquation;
