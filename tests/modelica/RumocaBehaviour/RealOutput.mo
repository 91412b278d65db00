within RumocaBehaviour;
connector RealOutput = output Real "An output signal";
