//! Engineering units: the UNECE codes of `EUInformation.UnitId` mapped to Modelica unit strings.
//!
//! Provenance: the codes and UnitIds are those of `UNECE_to_OPCUA.csv` published by the OPC Foundation in
//! the UA-Nodeset repository (`Schema/UNECE_to_OPCUA.csv`, OPC UA Part 8, 5.6.3). The table holds the units
//! that occur in the EngineeringUnits values of the UA-Nodeset corpus, plus the common mechanical units of
//! robotics; the Modelica column is ours (MLS 19.1 unit syntax: `.` multiplies, exponents follow the symbol,
//! `degC` for degree Celsius). A UnitId that is not in the table gets no `unit` attribute; the generated
//! code then says so in a comment, because a wrong unit is worse than none. Percent and ppm have no Modelica
//! unit (the value would be off by a factor if declared `"1"`), so they are deliberately absent.

/// (UNECE common code, Modelica unit).
const UNITS: &[(&str, &str)] = &[
    ("2A", "rad/s"),
    ("2M", "cm/s"),
    ("2Z", "mV"),
    ("41", "ml/min"),
    ("A97", "hPa"),
    ("AMP", "A"),
    ("B10", "bit/s"),
    ("B98", "us"),
    ("BAR", "bar"),
    ("C26", "ms"),
    ("C70", "pA"),
    ("C81", "rad"),
    ("C94", "min-1"),
    ("CEL", "degC"),
    ("D44", "var"),
    ("DAY", "d"),
    ("DD", "deg"),
    ("E20", "Mbit/s"),
    ("E32", "l/h"),
    ("E90", "cm-1"),
    ("GRM", "g"),
    ("HUR", "h"),
    ("HZ", "Hz"),
    ("KEL", "K"),
    ("KGM", "kg"),
    ("KMH", "km/h"),
    ("KWT", "kW"),
    ("L2", "l/min"),
    ("LTR", "l"),
    ("M1", "rad/s2"),
    ("MBR", "mbar"),
    ("MIN", "min"),
    ("MLT", "ml"),
    ("MMT", "mm"),
    ("MSK", "m/s2"),
    ("MTK", "m2"),
    ("MTQ", "m3"),
    ("MTR", "m"),
    ("MTS", "m/s"),
    ("NEU", "N"),
    ("NU", "N.m"),
    ("OHM", "Ohm"),
    ("PAL", "Pa"),
    ("SEC", "s"),
    ("TNE", "t"),
    ("VLT", "V"),
    ("WHR", "W.h"),
    ("WTT", "W"),
];

/// The UnitId of a UNECE common code: its ASCII bytes as a big-endian number (OPC UA Part 8, 5.6.3).
pub fn unit_id(code: &str) -> i32 {
    code.bytes().fold(0i32, |acc, b| (acc << 8) | b as i32)
}

/// The Modelica unit of a UnitId from the UNECE namespace, if the table has it.
pub fn modelica_unit(unit_id_value: i32) -> Option<&'static str> {
    UNITS.iter().find(|(code, _)| unit_id(code) == unit_id_value).map(|(_, u)| *u)
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
        assert_eq!(modelica_unit(4_408_652), Some("degC"));
        assert_eq!(modelica_unit(5_067_858), Some("m"));
        assert_eq!(modelica_unit(20_529), None, "percent has no Modelica unit");
    }

    #[test]
    fn every_unit_is_written_in_modelica_unit_syntax() {
        for (code, unit) in UNITS {
            assert!(unit.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '/' | '-')), "{code}: {unit}");
        }
        let mut codes: Vec<&str> = UNITS.iter().map(|(c, _)| *c).collect();
        codes.sort();
        codes.dedup();
        assert_eq!(codes.len(), UNITS.len(), "a code is listed twice");
    }
}
