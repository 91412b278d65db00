within RumocaBehaviour;
model Mid "No PS of its own; holds an axis"
  MyAxis a "The axis";
end Mid;
