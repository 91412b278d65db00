within Planted;
model PinnedOverride "Plugs in SubModified, but Holder's m keeps C = Empty, which has no inn"
  extends Planted.Holder(redeclare model M = Planted.SubModified);
end PinnedOverride;
