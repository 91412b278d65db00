within PymocaBehaviour;
model StatItem "An item that chooses Stat for S and sets its parameter"
  extends Item(redeclare model S = Stat, s(giveAway = 1));
end StatItem;
