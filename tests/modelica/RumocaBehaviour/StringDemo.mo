within RumocaBehaviour;
model StringDemo "A String variable: rumoca 0.10.2 compiles the model but cannot simulate it"
  Integer n(start=1, fixed=true) "A state number";
  String text = if n == 1 then "one" else "two" "Its text";
equation
  when time > 0.5 then
    n = 2;
  end when;
  annotation (experiment(StopTime=1, Interval=0.1));
end StringDemo;
