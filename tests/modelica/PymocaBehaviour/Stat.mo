within PymocaBehaviour;
model Stat "A class with a parameter Empty lacks"
  extends Empty;
  parameter Real giveAway = 0 "A parameter";
end Stat;
