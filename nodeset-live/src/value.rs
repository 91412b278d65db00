//! What the server and the client share: NodeIds as the Modelica blocks write them, the three Modelica
//! scalar types and their OPC UA variants, and failures as a status code with a message.

use opcua::types::{Identifier, LocalizedText, NamespaceMap, NodeId, StatusCode, Variant};
use std::str::FromStr;

/// A failed call: the OPC UA status the Modelica block's `status` output gets, and the message its
/// error function returns.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// The status (never Good).
    pub status: StatusCode,
    /// What went wrong and what to do about it.
    pub message: String,
}

impl Failure {
    /// A failure with its status and message.
    pub fn new(status: StatusCode, message: impl Into<String>) -> Failure {
        Failure {
            status,
            message: message.into(),
        }
    }
}

/// The status as the `Integer` a Modelica block gets: 0 for Good, else the 32 bits of the OPC UA status
/// code (negative for Bad, whose top bit is set).
pub fn status_int(status: StatusCode) -> i32 {
    if status.is_good() {
        0
    } else {
        status.bits() as i32
    }
}

/// A NodeId as written in a block's `nodeId` parameter: `nsu=<namespace URI>;i=5` (also `s=`, `g=`, `b=`),
/// `ns=2;i=5`, or `i=5` in the OPC UA namespace.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum NodeRef {
    /// Named by namespace URI: resolved against the namespace table of the server.
    Uri(String, Identifier),
    /// Named by namespace index.
    Index(NodeId),
}

impl NodeRef {
    /// Reads the text of a `nodeId` parameter.
    pub fn parse(text: &str) -> Result<NodeRef, Failure> {
        let invalid = |why: &str| {
            Failure::new(
                StatusCode::BadNodeIdInvalid,
                format!("`{text}` is not a NodeId: {why}; write nsu=<namespace URI>;i=<number> (or s=, g=, b=), ns=<index>;i=<number> or i=<number>"),
            )
        };
        let text_trimmed = text.trim();
        if text_trimmed.is_empty() {
            return Err(invalid("it is empty"));
        }
        if let Some(rest) = text_trimmed.strip_prefix("nsu=") {
            let (uri, id) = rest
                .rsplit_once(';')
                .ok_or_else(|| invalid("no `;` after the namespace URI"))?;
            let uri = uri
                .replace("%3b", ";")
                .replace("%3B", ";")
                .replace("%25", "%");
            if uri.is_empty() {
                return Err(invalid("the namespace URI is empty"));
            }
            let id = Identifier::from_str(id)
                .map_err(|_| invalid("the identifier is not i=, s=, g= or b="))?;
            return Ok(NodeRef::Uri(uri, id));
        }
        NodeId::from_str(text_trimmed)
            .map(NodeRef::Index)
            .map_err(|_| invalid("it is not in the form of OPC UA Part 6, 5.3.1.10"))
    }

    /// The NodeId on a server whose namespace table is `namespaces`.
    pub fn resolve(&self, namespaces: &NamespaceMap, text: &str) -> Result<NodeId, Failure> {
        match self {
            NodeRef::Index(id) => Ok(id.clone()),
            NodeRef::Uri(uri, id) => match namespaces.get_index(uri) {
                Some(ns) => Ok(NodeId::new(ns, id.clone())),
                None => Err(Failure::new(
                    StatusCode::BadNodeIdUnknown,
                    format!(
                        "`{text}`: the server has no namespace `{uri}`; its namespaces are {}",
                        list(namespaces)
                    ),
                )),
            },
        }
    }
}

fn list(namespaces: &NamespaceMap) -> String {
    let mut known: Vec<(&String, &u16)> = namespaces.known_namespaces().iter().collect();
    known.sort_by_key(|(_, i)| **i);
    known
        .iter()
        .map(|(u, _)| format!("`{u}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The Modelica scalar type a block reads or writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `Real`: `double`.
    Real,
    /// `Integer`: `int`.
    Integer,
    /// `Boolean`: `int`, 0 or 1.
    Boolean,
    /// `String`: `const char*`.
    String,
}

impl Kind {
    /// The Modelica name.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Real => "Real",
            Kind::Integer => "Integer",
            Kind::Boolean => "Boolean",
            Kind::String => "String",
        }
    }
}

/// A value of a Modelica block, before it becomes an OPC UA variant.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A `Real`.
    Real(f64),
    /// An `Integer`.
    Integer(i32),
    /// A `Boolean`.
    Boolean(bool),
    /// A `String`.
    String(String),
}

impl Value {
    /// Its kind.
    pub fn kind(&self) -> Kind {
        match self {
            Value::Real(_) => Kind::Real,
            Value::Integer(_) => Kind::Integer,
            Value::Boolean(_) => Kind::Boolean,
            Value::String(_) => Kind::String,
        }
    }
}

/// The scalar variants a value of `kind` may become, the likeliest first: a server checks the variant
/// against the variable's DataType, and the first it accepts is kept for the variable.
pub fn candidates(kind: Kind) -> &'static [Builtin] {
    match kind {
        Kind::Real => &[Builtin::Double, Builtin::Float],
        Kind::Integer => &[
            Builtin::Int32,
            Builtin::Int16,
            Builtin::Int64,
            Builtin::UInt32,
            Builtin::UInt16,
            Builtin::UInt64,
            Builtin::Byte,
            Builtin::SByte,
        ],
        Kind::Boolean => &[Builtin::Boolean],
        Kind::String => &[Builtin::String, Builtin::LocalizedText],
    }
}

/// The OPC UA built-in types a Modelica scalar is written as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builtin {
    /// Double.
    Double,
    /// Float.
    Float,
    /// SByte.
    SByte,
    /// Byte.
    Byte,
    /// Int16.
    Int16,
    /// UInt16.
    UInt16,
    /// Int32.
    Int32,
    /// UInt32.
    UInt32,
    /// Int64.
    Int64,
    /// UInt64.
    UInt64,
    /// Boolean.
    Boolean,
    /// String.
    String,
    /// LocalizedText (a String written with no locale; its text read).
    LocalizedText,
}

impl Builtin {
    /// The built-in type of a scalar variant, if it is one of those above.
    pub fn of(v: &Variant) -> Option<Builtin> {
        Some(match v {
            Variant::Double(_) => Builtin::Double,
            Variant::Float(_) => Builtin::Float,
            Variant::SByte(_) => Builtin::SByte,
            Variant::Byte(_) => Builtin::Byte,
            Variant::Int16(_) => Builtin::Int16,
            Variant::UInt16(_) => Builtin::UInt16,
            Variant::Int32(_) => Builtin::Int32,
            Variant::UInt32(_) => Builtin::UInt32,
            Variant::Int64(_) => Builtin::Int64,
            Variant::UInt64(_) => Builtin::UInt64,
            Variant::Boolean(_) => Builtin::Boolean,
            Variant::String(_) => Builtin::String,
            Variant::LocalizedText(_) => Builtin::LocalizedText,
            _ => return None,
        })
    }

    /// The built-in type of the OPC UA DataType `i=<n>` (the numeric ns0 types and Duration, a Double).
    pub fn of_data_type(id: &NodeId) -> Option<Builtin> {
        match (id.namespace, &id.identifier) {
            (0, Identifier::Numeric(n)) => Some(match n {
                1 => Builtin::Boolean,
                2 => Builtin::SByte,
                3 => Builtin::Byte,
                4 => Builtin::Int16,
                5 => Builtin::UInt16,
                6 => Builtin::Int32,
                7 => Builtin::UInt32,
                8 => Builtin::Int64,
                9 => Builtin::UInt64,
                10 => Builtin::Float,
                11 | 290 => Builtin::Double,
                12 => Builtin::String,
                21 => Builtin::LocalizedText,
                _ => return None,
            }),
            _ => None,
        }
    }

    /// `value` as a variant of this type, or why it cannot be (a Boolean is not a number, 300 is no Byte).
    pub fn variant(self, value: &Value) -> Result<Variant, String> {
        let int = |v: &Value| -> Result<i64, String> {
            match v {
                Value::Integer(i) => Ok(i64::from(*i)),
                other => Err(format!(
                    "a Modelica {} is not written as {self:?}",
                    other.kind().name()
                )),
            }
        };
        let fits = |i: i64, lo: i64, hi: i64| -> Result<i64, String> {
            if (lo..=hi).contains(&i) {
                Ok(i)
            } else {
                Err(format!(
                    "{i} is out of the range of {self:?} ({lo} to {hi})"
                ))
            }
        };
        Ok(match (self, value) {
            (Builtin::Double, Value::Real(r)) => Variant::Double(*r),
            (Builtin::Float, Value::Real(r)) => Variant::Float(*r as f32),
            (Builtin::Boolean, Value::Boolean(b)) => Variant::Boolean(*b),
            (Builtin::String, Value::String(t)) => Variant::from(t.as_str()),
            (Builtin::LocalizedText, Value::String(t)) => Variant::from(LocalizedText::new("", t)),
            (Builtin::SByte, v) => {
                Variant::SByte(fits(int(v)?, i8::MIN.into(), i8::MAX.into())? as i8)
            }
            (Builtin::Byte, v) => Variant::Byte(fits(int(v)?, 0, u8::MAX.into())? as u8),
            (Builtin::Int16, v) => {
                Variant::Int16(fits(int(v)?, i16::MIN.into(), i16::MAX.into())? as i16)
            }
            (Builtin::UInt16, v) => Variant::UInt16(fits(int(v)?, 0, u16::MAX.into())? as u16),
            (Builtin::Int32, v) => Variant::Int32(int(v)? as i32),
            (Builtin::UInt32, v) => Variant::UInt32(fits(int(v)?, 0, i64::from(u32::MAX))? as u32),
            (Builtin::Int64, v) => Variant::Int64(int(v)?),
            (Builtin::UInt64, v) => Variant::UInt64(fits(int(v)?, 0, i64::MAX)? as u64),
            (b, v) => {
                return Err(format!(
                    "a Modelica {} is not written as {b:?}",
                    v.kind().name()
                ))
            }
        })
    }
}

/// A variant read from a server as a Modelica value of `kind`: any number for a Real; an integer that
/// fits 32 bits for an Integer; a Boolean for a Boolean.
pub fn from_variant(v: &Variant, kind: Kind) -> Result<Value, String> {
    let wrong = || {
        format!(
            "the value {} is not a Modelica {}",
            describe(v),
            kind.name()
        )
    };
    match kind {
        Kind::Real => Ok(Value::Real(match v {
            Variant::Double(x) => *x,
            Variant::Float(x) => f64::from(*x),
            Variant::SByte(x) => f64::from(*x),
            Variant::Byte(x) => f64::from(*x),
            Variant::Int16(x) => f64::from(*x),
            Variant::UInt16(x) => f64::from(*x),
            Variant::Int32(x) => f64::from(*x),
            Variant::UInt32(x) => f64::from(*x),
            Variant::Int64(x) => *x as f64,
            Variant::UInt64(x) => *x as f64,
            _ => return Err(wrong()),
        })),
        Kind::Integer => {
            let i: i64 = match v {
                Variant::SByte(x) => (*x).into(),
                Variant::Byte(x) => (*x).into(),
                Variant::Int16(x) => (*x).into(),
                Variant::UInt16(x) => (*x).into(),
                Variant::Int32(x) => (*x).into(),
                Variant::UInt32(x) => (*x).into(),
                Variant::Int64(x) => *x,
                Variant::UInt64(x) => i64::try_from(*x).unwrap_or(i64::MAX),
                _ => return Err(wrong()),
            };
            i32::try_from(i)
                .map(Value::Integer)
                .map_err(|_| format!("the value {i} does not fit a Modelica Integer (32 bits)"))
        }
        Kind::Boolean => match v {
            Variant::Boolean(b) => Ok(Value::Boolean(*b)),
            _ => Err(wrong()),
        },
        Kind::String => match v {
            Variant::String(t) => Ok(Value::String(t.as_ref().to_owned())),
            Variant::LocalizedText(t) => Ok(Value::String(t.text.as_ref().to_owned())),
            _ => Err(wrong()),
        },
    }
}

/// A variant for messages: `String "abc"`, `Double 1.5`, `Empty`.
pub fn describe(v: &Variant) -> String {
    match v {
        Variant::Empty => "Empty (the variable has no value)".into(),
        Variant::String(s) => format!("String {:?}", s.as_ref()),
        Variant::Array(_) => "an array".into(),
        other => {
            let text = format!("{other:?}");
            text.replacen('(', " ", 1).trim_end_matches(')').to_string()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_ids_in_the_forms_the_blocks_write() {
        assert_eq!(
            NodeRef::parse("nsu=http://example.com/a;b/;i=6001").unwrap(),
            NodeRef::Uri("http://example.com/a;b/".into(), Identifier::Numeric(6001)),
            "the identifier follows the last `;`"
        );
        assert_eq!(
            NodeRef::parse("nsu=urn:x%3by;s=Motor.Speed").unwrap(),
            NodeRef::Uri("urn:x;y".into(), Identifier::String("Motor.Speed".into()))
        );
        assert_eq!(
            NodeRef::parse("ns=2;i=5").unwrap(),
            NodeRef::Index(NodeId::new(2, 5u32))
        );
        assert_eq!(
            NodeRef::parse("i=2258").unwrap(),
            NodeRef::Index(NodeId::new(0, 2258u32))
        );
        for bad in [
            "",
            "nsu=;i=5",
            "nsu=urn:x",
            "nsu=urn:x;q=5",
            "ns=x;i=5",
            "6001",
        ] {
            let e = NodeRef::parse(bad).unwrap_err();
            assert_eq!(e.status, StatusCode::BadNodeIdInvalid, "{bad}");
            assert!(
                e.message.contains("nsu=<namespace URI>;i=<number>"),
                "{bad}: the message shows the form: {}",
                e.message
            );
        }
    }

    #[test]
    fn values_convert_within_range_only() {
        assert_eq!(
            Builtin::Byte.variant(&Value::Integer(255)),
            Ok(Variant::Byte(255))
        );
        assert!(Builtin::Byte
            .variant(&Value::Integer(256))
            .unwrap_err()
            .contains("out of the range of Byte"));
        assert!(Builtin::UInt32.variant(&Value::Integer(-1)).is_err());
        assert!(Builtin::Double.variant(&Value::Boolean(true)).is_err());
        assert_eq!(
            from_variant(&Variant::Float(1.5), Kind::Real),
            Ok(Value::Real(1.5))
        );
        assert_eq!(
            from_variant(&Variant::UInt16(7), Kind::Integer),
            Ok(Value::Integer(7))
        );
        assert!(from_variant(&Variant::Int64(1 << 40), Kind::Integer)
            .unwrap_err()
            .contains("does not fit"));
        let e = from_variant(&Variant::from("abc"), Kind::Real).unwrap_err();
        assert!(e.contains("String \"abc\" is not a Modelica Real"), "{e}");
        assert_eq!(status_int(StatusCode::Good), 0);
        assert!(
            status_int(StatusCode::BadNodeIdUnknown) < 0,
            "Bad codes are negative Integers"
        );
    }
}
