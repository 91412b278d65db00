within Planted;
model Inner "Has one parameter, v"
  parameter Real v = 0;
end Inner;
