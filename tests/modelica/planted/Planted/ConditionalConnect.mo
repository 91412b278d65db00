within Planted;
model ConditionalConnect "Uses a conditional component only in a connection and a modifier (valid)"
  parameter Boolean usePart = false;
  Planted.Part part(v(start=1)) if usePart;
  Planted.Part other;
equation
  connect(part, other);
  other.v = 1;
end ConditionalConnect;
