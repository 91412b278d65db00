within Planted;
connector Part "A connector with one signal"
  Real v;
end Part;
