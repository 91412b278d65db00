within Planted;
model ConditionalBinding "Binds y to a member of a conditional component"
  parameter Boolean usePart = false;
  Planted.Part part if usePart;
  Real y = part.v;
end ConditionalBinding;
