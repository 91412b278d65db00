//! Engineering units: the UNECE codes of `EUInformation.UnitId` mapped to SI units, as the Modelica Standard
//! Library declares quantities (`Modelica.Units.SI.Length = Real(final quantity="Length", final unit="m")`,
//! shown in `displayUnit="mm"`).
//!
//! A Modelica variable holds the SI value: a variable whose EngineeringUnits say millimetre is declared
//! `unit="m", displayUnit="mm", quantity="Length"`, and a value the nodeset gives it is converted to metres.
//! The OPC UA value is in the engineering unit, so the `__OPCUA` annotation keeps the code and the conversion
//! (`engineeringUnit="MMT", siFactor=0.001`, plus `siOffset` for degree Celsius): SI value = siFactor * OPC UA
//! value + siOffset. A binding to a server applies it both ways.
//!
//! Provenance: the codes, UnitIds and symbols are those of `UNECE_to_OPCUA.csv` published by the OPC
//! Foundation in the UA-Nodeset repository (`Schema/UNECE_to_OPCUA.csv`, OPC UA Part 8, 5.6.3); the test
//! `every_code_is_a_row_of_the_csv` checks each against that file. The table holds the units that occur in the
//! EngineeringUnits values of the UA-Nodeset corpus, plus the common mechanical units of robotics; the SI
//! columns are ours (MLS 19.1 unit syntax: `.` multiplies, exponents follow the symbol, `degC` for degree
//! Celsius; quantities named as in `Modelica.Units.SI`). A UnitId that is not in the table gets no `unit`
//! attribute; the generated code then says so in a comment, because a wrong unit is worse than none. Percent
//! and ppm are absent: their SI unit would be `"1"`, and no display unit for them is a Modelica unit
//! expression.

/// An engineering unit as Modelica declares it.
#[derive(Debug, PartialEq)]
pub struct Unit {
    /// The UNECE common code (`MMT`).
    pub code: &'static str,
    /// The SI unit of the Modelica value (`m`).
    pub si: &'static str,
    /// The unit the value is shown in, where it is not the SI unit (`mm`).
    pub display: Option<&'static str>,
    /// The quantity, as `Modelica.Units.SI` names it (`Length`); empty where it has none (bit/s).
    pub quantity: &'static str,
    /// SI value = factor * value in the engineering unit + offset.
    pub factor: f64,
    /// The offset of that conversion.
    pub offset: f64,
}

impl Unit {
    /// The value in SI of a value in the engineering unit.
    pub fn to_si(&self, x: f64) -> f64 {
        if self.is_si() {
            x
        } else {
            x * self.factor + self.offset
        }
    }

    /// Whether values need no conversion.
    pub fn is_si(&self) -> bool {
        self.factor == 1.0 && self.offset == 0.0
    }

    /// The attributes of a declaration (`unit="m"`, `displayUnit="mm"`, `quantity="Length"`), as `name=value`.
    pub fn attrs(&self) -> Vec<String> {
        let q = |s: &str| format!("\"{s}\"");
        let mut a = vec![format!("unit={}", q(self.si))];
        if let Some(d) = self.display {
            a.push(format!("displayUnit={}", q(d)));
        }
        if !self.quantity.is_empty() {
            a.push(format!("quantity={}", q(self.quantity)));
        }
        a
    }
}

const fn u(code: &'static str, si: &'static str, display: Option<&'static str>, quantity: &'static str, factor: f64) -> Unit {
    Unit { code, si, display, quantity, factor, offset: 0.0 }
}

const PI: f64 = std::f64::consts::PI;

/// The units, sorted by code.
const UNITS: &[Unit] = &[
    u("2A", "rad/s", None, "AngularVelocity", 1.0),
    u("2B", "rad/s2", None, "AngularAcceleration", 1.0),
    u("2M", "m/s", Some("cm/s"), "Velocity", 0.01),
    u("2Z", "V", Some("mV"), "ElectricPotential", 1e-3),
    u("41", "m3/s", Some("ml/min"), "VolumeFlowRate", 1e-6 / 60.0),
    u("A97", "Pa", Some("hPa"), "Pressure", 100.0),
    u("AMP", "A", None, "ElectricCurrent", 1.0),
    u("B10", "bit/s", None, "", 1.0),
    u("B98", "s", Some("us"), "Time", 1e-6),
    u("BAR", "Pa", Some("bar"), "Pressure", 1e5),
    u("C26", "s", Some("ms"), "Time", 1e-3),
    u("C70", "A", Some("pA"), "ElectricCurrent", 1e-12),
    u("C81", "rad", None, "Angle", 1.0),
    u("C94", "s-1", Some("min-1"), "Frequency", 1.0 / 60.0),
    Unit { code: "CEL", si: "K", display: Some("degC"), quantity: "ThermodynamicTemperature", factor: 1.0, offset: 273.15 },
    u("D44", "var", None, "ReactivePower", 1.0),
    u("DAY", "s", Some("d"), "Time", 86_400.0),
    u("DD", "rad", Some("deg"), "Angle", PI / 180.0),
    u("E20", "bit/s", Some("Mbit/s"), "", 1e6),
    u("E32", "m3/s", Some("l/h"), "VolumeFlowRate", 1e-3 / 3600.0),
    u("E90", "m-1", Some("cm-1"), "WaveNumber", 100.0),
    u("GRM", "kg", Some("g"), "Mass", 1e-3),
    u("HTZ", "Hz", None, "Frequency", 1.0),
    u("HUR", "s", Some("h"), "Time", 3600.0),
    u("KEL", "K", None, "ThermodynamicTemperature", 1.0),
    u("KGM", "kg", None, "Mass", 1.0),
    u("KMH", "m/s", Some("km/h"), "Velocity", 1.0 / 3.6),
    u("KWT", "W", Some("kW"), "Power", 1e3),
    u("L2", "m3/s", Some("l/min"), "VolumeFlowRate", 1e-3 / 60.0),
    u("LTR", "m3", Some("l"), "Volume", 1e-3),
    u("MBR", "Pa", Some("mbar"), "Pressure", 100.0),
    u("MIN", "s", Some("min"), "Time", 60.0),
    u("MLT", "m3", Some("ml"), "Volume", 1e-6),
    u("MMT", "m", Some("mm"), "Length", 1e-3),
    u("MSK", "m/s2", None, "Acceleration", 1.0),
    u("MTK", "m2", None, "Area", 1.0),
    u("MTQ", "m3", None, "Volume", 1.0),
    u("MTR", "m", None, "Length", 1.0),
    u("MTS", "m/s", None, "Velocity", 1.0),
    u("NEW", "N", None, "Force", 1.0),
    u("NU", "N.m", None, "Torque", 1.0),
    u("OHM", "Ohm", None, "Resistance", 1.0),
    u("PAL", "Pa", None, "Pressure", 1.0),
    u("SEC", "s", None, "Time", 1.0),
    u("TNE", "kg", Some("t"), "Mass", 1e3),
    u("VLT", "V", None, "ElectricPotential", 1.0),
    u("WHR", "J", Some("W.h"), "Energy", 3600.0),
    u("WTT", "W", None, "Power", 1.0),
];

/// The UnitId of a UNECE common code: its ASCII bytes as a big-endian number (OPC UA Part 8, 5.6.3).
pub fn unit_id(code: &str) -> i32 {
    code.bytes().fold(0i32, |acc, b| (acc << 8) | b as i32)
}

/// The unit of a UnitId from the UNECE namespace, if the table has it.
pub fn modelica_unit(unit_id_value: i32) -> Option<&'static Unit> {
    UNITS.iter().find(|unit| unit_id(unit.code) == unit_id_value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_ids_follow_the_csv() {
        // Rows of UNECE_to_OPCUA.csv.
        assert_eq!(unit_id("C81"), 4_405_297);
        assert_eq!(unit_id("CEL"), 4_408_652);
        assert_eq!(unit_id("P1"), 20_529);
        assert_eq!(unit_id("2Z"), 12_890);
        assert_eq!(unit_id("59"), 13_625);
        assert_eq!(modelica_unit(4_408_652).map(|u| u.si), Some("K"));
        assert_eq!(modelica_unit(5_067_858).map(|u| u.si), Some("m"));
        assert_eq!(modelica_unit(20_529), None, "percent has no Modelica unit");
    }

    #[test]
    fn values_are_converted_to_si() {
        let unit = |code| modelica_unit(unit_id(code)).unwrap();
        assert_eq!(unit("MMT").to_si(12.5), 0.0125);
        assert_eq!(unit("CEL").to_si(20.0), 293.15);
        assert_eq!(unit("DD").to_si(180.0), PI);
        assert_eq!(unit("HUR").to_si(2.0), 7200.0);
        assert_eq!(unit("MTR").to_si(0.1), 0.1);
        assert_eq!(unit("MMT").attrs(), ["unit=\"m\"", "displayUnit=\"mm\"", "quantity=\"Length\""]);
        assert_eq!(unit("B10").attrs(), ["unit=\"bit/s\""]);
    }

    /// Each code, with its symbol, is a row of the OPC Foundation's table in the UA-Nodeset tree (the symbol
    /// written in Modelica unit syntax is the display unit, or the SI unit where none is given).
    #[test]
    fn every_code_is_a_row_of_the_csv() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/nodesets/ua-nodeset/Schema/UNECE_to_OPCUA.csv");
        let csv = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (the UA-Nodeset tree is ../shared/nodesets/ua-nodeset beside the checkout)", path.display()));
        let modelica_syntax = |s: &str| {
            s.replace('\u{b5}', "u")
                .replace('\u{b0}', "deg")
                .replace('\u{b2}', "2")
                .replace('\u{b3}', "3")
                .replace("\u{207b}\u{b9}", "-1")
                .replace('\u{b7}', ".")
                .replace(['\u{3a9}', '\u{2126}'], "Ohm")
        };
        for unit in UNITS {
            let row = csv
                .lines()
                .find(|l| l.split(',').next() == Some(unit.code))
                .unwrap_or_else(|| panic!("{} is not a code of {}", unit.code, path.display()));
            let fields: Vec<&str> = row.split(',').collect();
            assert_eq!(fields[1].parse::<i32>().unwrap(), unit_id(unit.code), "{row}");
            let symbol = modelica_syntax(fields[2].trim_matches('"'));
            let shown = unit.display.unwrap_or(unit.si);
            assert_eq!(shown, symbol, "{row}");
        }
    }

    #[test]
    fn every_unit_is_written_in_modelica_unit_syntax() {
        for unit in UNITS {
            for s in [unit.si].into_iter().chain(unit.display) {
                assert!(s.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '/' | '-')), "{}: {s}", unit.code);
            }
            assert!(unit.factor > 0.0, "{}", unit.code);
        }
        let codes: Vec<&str> = UNITS.iter().map(|u| u.code).collect();
        let mut sorted = codes.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(codes, sorted, "codes are listed once, in order");
    }
}
