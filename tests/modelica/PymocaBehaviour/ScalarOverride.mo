within PymocaBehaviour;
model ScalarOverride "Plugs in StatItem and repeats its choice of S on the item"
  extends ScalarHolder(redeclare model I = StatItem, item(redeclare model S = Stat));
end ScalarOverride;
