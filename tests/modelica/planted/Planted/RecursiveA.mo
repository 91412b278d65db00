within Planted;
model RecursiveA "Contains a RecursiveB, which contains a RecursiveA"
  Planted.RecursiveB b;
end RecursiveA;
