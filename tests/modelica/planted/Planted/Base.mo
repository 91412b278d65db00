within Planted;
model Base "Declares a replaceable class C and a component of it"
  replaceable model C = Planted.Empty;
  C c;
end Base;
