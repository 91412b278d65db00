within RumocaBehaviour;
connector RealInput = input Real "An input signal";
