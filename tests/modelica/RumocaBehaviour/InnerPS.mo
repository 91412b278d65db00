within RumocaBehaviour;
model InnerPS "The class the axis chooses: one input"
  extends Empty;
  RealInput pos "Position";
end InnerPS;
