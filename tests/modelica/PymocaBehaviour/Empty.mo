within PymocaBehaviour;
model Empty "Nothing"
end Empty;
