within PymocaBehaviour;
model ViaOverride "Plugs in StatItem and redeclares the alias"
  extends ViaHolder(redeclare model I = StatItem, redeclare model I_S = Stat);
end ViaOverride;
