within Planted;
model Empty "Nothing"
end Empty;
