within Planted;
model RecursiveB "Contains a RecursiveA"
  Planted.RecursiveA a;
end RecursiveB;
