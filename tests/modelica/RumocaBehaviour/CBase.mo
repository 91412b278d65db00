within RumocaBehaviour;
model CBase "Declares a replaceable component"
  replaceable Empty ps "Replaceable component";
end CBase;
