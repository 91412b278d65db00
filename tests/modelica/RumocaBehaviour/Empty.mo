within RumocaBehaviour;
model Empty "An empty class, the default of the replaceable classes"
end Empty;
