within PymocaBehaviour;
model ArrayOverride "The same with an array of items: valid, but pymoca keeps the declaration's choice"
  extends ArrayHolder(redeclare model I = StatItem, items(redeclare model S = Stat));
end ArrayOverride;
