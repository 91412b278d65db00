//! DataTypes: how an OPC UA DataType is written in Modelica, the classes of `<Pkg>.Types`, and values as
//! Modelica literals.

use super::ctx::{node_id_text, Ctx};
use super::plan::{Base, MType, RecField, RecordInfo};
use super::text::{self, string_literal};
use crate::model::{ids, DataTypeKind, EnumValue, Field, NodeIx, StructureKind};
use crate::nodeid::{format_guid, QualifiedName};
use crate::source::FileId;
use crate::value::{BuiltinType, Structure, Variant};
use std::collections::BTreeSet;
use std::rc::Rc;

/// How a built-in type maps: its base, attributes, and whether it needs a `type` of its own in `OpcUa.Types`.
struct BuiltinMap {
    base: Base,
    alias: bool,
    min: Option<&'static str>,
    max: Option<&'static str>,
    unit: Option<&'static str>,
    doc: &'static str,
}

fn builtin_map(b: BuiltinType) -> Result<BuiltinMap, &'static str> {
    use BuiltinType as B;
    let map = |base, alias, min, max, unit, doc| Ok(BuiltinMap { base, alias, min, max, unit, doc });
    match b {
        B::Boolean => map(Base::Boolean, false, None, None, None, ""),
        B::SByte => map(Base::Integer, true, Some("-128"), Some("127"), None, "Signed 8-bit integer"),
        B::Byte => map(Base::Integer, true, Some("0"), Some("255"), None, "Unsigned 8-bit integer"),
        B::Int16 => map(Base::Integer, true, Some("-32768"), Some("32767"), None, "Signed 16-bit integer"),
        B::UInt16 => map(Base::Integer, true, Some("0"), Some("65535"), None, "Unsigned 16-bit integer"),
        B::Int32 => map(Base::Integer, false, None, None, None, ""),
        B::UInt32 => map(
            Base::Integer,
            true,
            Some("0"),
            None,
            None,
            "Unsigned 32-bit integer; a Modelica Integer has 32 signed bits, so values above 2147483647 cannot be represented",
        ),
        B::Int64 => map(
            Base::Real,
            true,
            None,
            None,
            None,
            "Signed 64-bit integer as a Real, exact up to 2^53 in magnitude (a Modelica Integer has 32 bits)",
        ),
        B::UInt64 => map(Base::Real, true, Some("0"), None, None, "Unsigned 64-bit integer as a Real, exact up to 2^53"),
        B::Float | B::Double => map(Base::Real, false, None, None, None, ""),
        B::String => map(Base::String, false, None, None, None, ""),
        B::DateTime => map(
            Base::Real,
            true,
            None,
            None,
            Some("s"),
            "Seconds since 1970-01-01T00:00:00Z; OPC UA counts steps of 100 ns since 1601, so fractions below a microsecond are lost",
        ),
        B::Guid => map(Base::String, true, None, None, None, "A Guid in its text form 01234567-89ab-cdef-0123-456789abcdef"),
        B::NodeId => map(
            Base::String,
            true,
            None,
            None,
            None,
            "A NodeId in its text form: nsu=<namespace URI>;i=<number> (i=<number> in the base namespace)",
        ),
        B::ExpandedNodeId => map(Base::String, true, None, None, None, "An ExpandedNodeId in its text form nsu=<namespace URI>;i=<number>"),
        B::StatusCode => map(
            Base::Integer,
            true,
            None,
            None,
            None,
            "A StatusCode as the signed 32-bit integer with the same bits: Bad codes are negative",
        ),
        B::QualifiedName => map(Base::String, true, None, None, None, "A QualifiedName as nsu=<namespace URI>;<Name> (<Name> in the base namespace)"),
        B::LocalizedText => map(Base::String, true, None, None, None, "The text of a LocalizedText in the default locale of the nodeset"),
        B::ByteString => Err("ByteString has no Modelica type"),
        B::XmlElement => Err("XmlElement has no Modelica type"),
        B::ExtensionObject => Err("an abstract Structure has no Modelica type (its fields are unknown)"),
        B::DataValue => Err("DataValue has no Modelica type"),
        B::Variant => Err("BaseDataType stands for any type (a Variant), which has no Modelica type"),
        B::DiagnosticInfo => Err("DiagnosticInfo has no Modelica type"),
    }
}

impl Ctx<'_> {
    /// The Modelica form of a DataType.
    pub fn mtype(&mut self, dt: NodeIx) -> MType {
        let Some(info) = self.m.data_types.get(&dt) else {
            return MType::Unmapped(format!("`{}` is not a DataType", self.m.qualified(dt)));
        };
        match info.kind.clone() {
            DataTypeKind::Builtin(b) => self.builtin_mtype(b, Some(dt)),
            DataTypeKind::AbstractBuiltin => match self.m.node(dt).id.ns0() {
                Some(ids::NUMBER) | Some(ids::DECIMAL) => MType::Scalar {
                    base: Base::Real,
                    class: None,
                    min: None,
                    max: None,
                    unit: None,
                    builtin: BuiltinType::Double,
                },
                Some(ids::INTEGER) => MType::Scalar {
                    base: Base::Integer,
                    class: None,
                    min: None,
                    max: None,
                    unit: None,
                    builtin: BuiltinType::Int32,
                },
                Some(ids::UINTEGER) => MType::Scalar {
                    base: Base::Integer,
                    class: None,
                    min: Some("0"),
                    max: None,
                    unit: None,
                    builtin: BuiltinType::UInt32,
                },
                Some(ids::STRUCTURE) => {
                    MType::Unmapped("an abstract Structure has no Modelica type (its fields are unknown)".into())
                }
                _ => MType::Unmapped(format!(
                    "{} stands for any type (a Variant), which has no Modelica type",
                    self.m.node(dt).browse_name.name
                )),
            },
            DataTypeKind::Simple(b) => match self.builtin_mtype(b, None) {
                MType::Scalar { base, min, max, unit, builtin, .. } => {
                    MType::Scalar { base, class: Some(self.datatype_path(dt)), min, max, unit, builtin }
                }
                MType::Unmapped(why) => {
                    MType::Unmapped(format!("{} is a {}: {why}", self.m.node(dt).browse_name.name, b.type_name()))
                }
                other => other,
            },
            DataTypeKind::Enumeration { values, .. } => {
                if values.is_empty() {
                    MType::Unmapped(format!("{} is an enumeration without values", self.m.node(dt).browse_name.name))
                } else {
                    MType::Enum { class: self.datatype_path(dt), dt }
                }
            }
            DataTypeKind::OptionSet { .. } => MType::Record { class: self.datatype_path(dt), dt },
            DataTypeKind::Structure { .. } if self.m.node(dt).id.ns0() == Some(ids::STRUCTURE) => {
                MType::Unmapped("an abstract Structure has no Modelica type (its fields are unknown)".into())
            }
            DataTypeKind::Structure { .. } => MType::Record { class: self.datatype_path(dt), dt },
        }
    }

    /// A built-in type; `dt` is its own DataType node when known.
    fn builtin_mtype(&mut self, b: BuiltinType, dt: Option<NodeIx>) -> MType {
        match builtin_map(b) {
            Ok(map) => {
                let class = if map.alias {
                    let node = dt.or_else(|| self.m.ns0(b.id()));
                    node.map(|n| self.datatype_path(n))
                } else {
                    None
                };
                MType::Scalar { base: map.base, class, min: map.min, max: map.max, unit: map.unit, builtin: b }
            }
            Err(why) => MType::Unmapped(why.to_string()),
        }
    }

    /// The literal identifiers of an enumeration, in the order of its values.
    pub fn enum_literals(&mut self, dt: NodeIx) -> Vec<(EnumValue, String)> {
        let values = match self.m.data_types.get(&dt).map(|i| &i.kind) {
            Some(DataTypeKind::Enumeration { values, .. }) => values.clone(),
            _ => return Vec::new(),
        };
        let mut scope = self.scope::<usize>();
        for (i, v) in values.iter().enumerate() {
            scope.add(&v.name, i);
        }
        let (names, collisions) = scope.finish();
        if !collisions.is_empty() {
            let what = format!("enumeration {}", self.m.qualified(dt));
            self.report(&what, "literals", collisions, |_| (dt, None));
        }
        values.into_iter().enumerate().map(|(i, v)| (v, names[&i].clone())).collect()
    }

    /// The field names of a structure or the bit names of an OptionSet, supertypes first.
    pub fn record_info(&mut self, dt: NodeIx) -> Rc<RecordInfo> {
        if let Some(r) = self.records.get(&dt) {
            return r.clone();
        }
        let kind = self.m.data_types.get(&dt).map(|i| i.kind.clone());
        let info = match kind {
            Some(DataTypeKind::Structure { kind, fields, .. }) => {
                // Extend the supertype's record when it is a structure with fields of its own.
                let sup = self.m.node(dt).super_type.filter(|&s| {
                    matches!(self.m.data_types.get(&s).map(|i| &i.kind), Some(DataTypeKind::Structure { fields, .. }) if !fields.is_empty())
                        && self.m.node(s).id.ns0() != Some(ids::STRUCTURE)
                });
                let base = sup.map(|s| self.record_info(s));
                let mut taken = base.as_ref().map(|b| b.taken.clone()).unwrap_or_default();
                let mut out: Vec<RecField> = base
                    .as_ref()
                    .map(|b| {
                        b.fields
                            .iter()
                            .cloned()
                            .map(|mut f| {
                                f.inherited = true;
                                f
                            })
                            .collect()
                    })
                    .unwrap_or_default();
                let inherited: BTreeSet<String> = out.iter().map(|f| f.name.clone()).collect();
                let own: Vec<Field> = fields.into_iter().filter(|f| !inherited.contains(&*f.name)).collect();
                let mut scope = self.scope::<usize>();
                for t in &taken {
                    scope.reserve(t);
                }
                if kind == StructureKind::Union {
                    scope.reserve("switchField");
                }
                for (i, f) in own.iter().enumerate() {
                    scope.add(&super::ctx::component_original(&f.name), i);
                }
                let (names, collisions) = scope.finish();
                let what = format!("record {}", self.m.qualified(dt));
                self.report(&what, "fields", collisions, |i| (dt, Some(own[*i].name.to_string())));
                if kind == StructureKind::Union {
                    taken.insert("switchField".into());
                }
                for (i, f) in own.into_iter().enumerate() {
                    let ident = names[&i].clone();
                    taken.insert(ident.clone());
                    let has_flag = (kind == StructureKind::StructureWithOptionalFields && f.is_optional).then(|| {
                        let mut flag = format!("has_{ident}");
                        while taken.contains(&flag) {
                            flag.push('_');
                        }
                        taken.insert(flag.clone());
                        flag
                    });
                    // An array of unknown length in a record gets its length as a field of its own: a record
                    // constructor cannot infer `[:]` (rumoca rejects it inside arrays of records).
                    let unknown_len =
                        Self::dims(f.value_rank, &f.array_dimensions).is_some_and(|d| d.len() == 1 && d[0].is_none());
                    let count = unknown_len.then(|| {
                        let mut c = super::ctx::count_name(&ident);
                        while taken.contains(&c) {
                            c.push('_');
                        }
                        taken.insert(c.clone());
                        c
                    });
                    out.push(RecField {
                        name: f.name.to_string(),
                        ident,
                        has_flag,
                        count,
                        description: f.description.clone(),
                        field: Some(f),
                        bit: None,
                        inherited: false,
                    });
                }
                RecordInfo { fields: out, taken, extends: sup }
            }
            Some(DataTypeKind::OptionSet { bits, .. }) => {
                let mut scope = self.scope::<usize>();
                for (i, b) in bits.iter().enumerate() {
                    scope.add(&super::ctx::component_original(&b.name), i);
                }
                let (names, collisions) = scope.finish();
                let what = format!("record {}", self.m.qualified(dt));
                self.report(&what, "bits", collisions, |i| (dt, Some(bits[*i].name.clone())));
                let fields: Vec<RecField> = bits
                    .iter()
                    .enumerate()
                    .map(|(i, b)| RecField {
                        name: b.name.clone(),
                        ident: names[&i].clone(),
                        has_flag: None,
                        count: None,
                        field: None,
                        bit: Some(b.value),
                        description: b.description.clone(),
                        inherited: false,
                    })
                    .collect();
                RecordInfo { taken: fields.iter().map(|f| f.ident.clone()).collect(), fields, extends: None }
            }
            _ => RecordInfo { fields: Vec::new(), taken: BTreeSet::new(), extends: None },
        };
        let info = Rc::new(info);
        self.records.insert(dt, info.clone());
        info
    }

    /// Whether the record of `dt` contains a record of `target`, through its fields (a Modelica record cannot
    /// contain itself).
    pub fn record_contains(&self, dt: NodeIx, target: NodeIx, seen: &mut BTreeSet<NodeIx>) -> bool {
        if !seen.insert(dt) {
            return false;
        }
        let Some(DataTypeKind::Structure { fields, .. }) = self.m.data_types.get(&dt).map(|i| &i.kind) else {
            return false;
        };
        fields.iter().any(|f| f.data_type == target || self.record_contains(f.data_type, target, seen))
    }

    /// The array dimensions of a declaration (`[3]`, `[:]`, `[2, 3]`) from a ValueRank and ArrayDimensions;
    /// `None` for a scalar. ValueRank 0 (one or more dimensions) is one dimension of any length; -2 (any) and
    /// -3 (scalar or one dimension) are declared as scalars.
    pub fn dims(value_rank: i32, array_dimensions: &[u32]) -> Option<Vec<Option<u32>>> {
        match value_rank {
            r if r >= 1 => {
                let r = r as usize;
                Some(
                    (0..r)
                        .map(|i| array_dimensions.get(i).copied().filter(|&d| d > 0 && array_dimensions.len() == r))
                        .collect(),
                )
            }
            0 => Some(vec![None]),
            _ => None,
        }
    }

    /// A default value of a type: zero, false, the empty string, the literal with value 0 (else the first), or
    /// the record with its defaults.
    pub fn default_literal(&mut self, ty: &MType) -> String {
        match ty {
            MType::Scalar { base: Base::Real, .. } => "0".into(),
            MType::Scalar { base: Base::Integer, min, .. } => match min {
                Some(m) if m.parse::<i64>().is_ok_and(|v| v > 0) => m.to_string(),
                _ => "0".into(),
            },
            MType::Scalar { base: Base::Boolean, .. } => "false".into(),
            MType::Scalar { base: Base::String, .. } => "\"\"".into(),
            MType::Enum { class, dt } => {
                let lits = self.enum_literals(*dt);
                let lit = lits
                    .iter()
                    .find(|(v, _)| v.value == 0)
                    .or(lits.first())
                    .map(|(_, n)| n.clone())
                    .unwrap_or_default();
                format!("{class}.{lit}")
            }
            MType::Record { class, .. } => format!("{class}()"),
            MType::Unmapped(_) => String::new(),
        }
    }

    /// `fill(default, d1, d2)` for an array, with 0 for a dimension of unknown length.
    pub fn default_array(&mut self, ty: &MType, dims: &[Option<u32>]) -> String {
        let d = self.default_literal(ty);
        // `fill(R(), n)` of a record is not accepted by rumoca for n > 0; an array literal is.
        if matches!(ty, MType::Record { .. })
            && dims.iter().all(|x| x.is_some_and(|n| n > 0))
            && dims.iter().map(|x| x.unwrap_or(0) as u64).product::<u64>() <= 4096
        {
            let mut lit = d;
            for n in dims.iter().rev() {
                let n = n.unwrap_or(0) as usize;
                lit = format!("{{{}}}", vec![lit; n].join(", "));
            }
            return lit;
        }
        let sizes: Vec<String> = dims.iter().map(|x| x.unwrap_or(0).to_string()).collect();
        format!("fill({d}, {})", sizes.join(", "))
    }

    /// A value as a literal of `ty`; `None` when it does not fit (the caller falls back to the default and says
    /// so).
    pub fn literal(&mut self, v: &Variant, ty: &MType, file: FileId) -> Option<String> {
        match (ty, v) {
            (_, Variant::Variant(inner)) => self.literal(inner, ty, file),
            (MType::Scalar { base: Base::Boolean, .. }, Variant::Boolean(b)) => Some(b.to_string()),
            (MType::Scalar { base: Base::Integer, builtin, .. }, v) => {
                let x = as_i128(v)?;
                if *builtin == BuiltinType::StatusCode {
                    return Some((x as u32 as i32).to_string());
                }
                i32::try_from(x).ok().map(|x| x.to_string())
            }
            (MType::Scalar { base: Base::Real, builtin, .. }, v) => {
                if *builtin == BuiltinType::DateTime {
                    return match v {
                        Variant::DateTime(t) => text::unix_seconds(t).and_then(text::real_literal),
                        _ => None,
                    };
                }
                match v {
                    // A Float's shortest text, read as a Double: `0.1`, not `0.10000000149011612`.
                    Variant::Float(f) => text::real_literal(f.to_string().parse().ok()?),
                    Variant::Double(f) => text::real_literal(*f),
                    other => as_i128(other).map(|x| x.to_string()),
                }
            }
            (MType::Scalar { base: Base::String, .. }, v) => self.string_value(v).map(|s| string_literal(&s)),
            (MType::Enum { class, dt }, v) => {
                let x = as_i128(v)?;
                let lits = self.enum_literals(*dt);
                lits.iter().find(|(e, _)| e.value as i128 == x).map(|(_, n)| format!("{class}.{n}"))
            }
            (MType::Record { dt, .. }, Variant::ExtensionObject(eo)) => {
                let s = eo.structure()?;
                self.record_literal(*dt, s, file)
            }
            _ => None,
        }
    }

    /// The text of a string-like value (String, LocalizedText, QualifiedName, NodeId, Guid, DateTime).
    pub fn string_value(&self, v: &Variant) -> Option<String> {
        Some(match v {
            Variant::String(s) => s.clone(),
            Variant::LocalizedText(t) => t.text.clone(),
            Variant::QualifiedName(q) => qualified_name_text(self, q),
            Variant::NodeId(id) | Variant::ExpandedNodeId(id) => node_id_text(self.m, id),
            Variant::Guid(g) => format_guid(g),
            Variant::DateTime(t) => t.clone(),
            Variant::Null => String::new(),
            _ => return None,
        })
    }

    /// An array value as `{a, b, c}` (nested for more dimensions), or `None` when an element does not fit.
    pub fn array_literal(&mut self, v: &Variant, ty: &MType, file: FileId) -> Option<String> {
        match v {
            Variant::Array(_, items) => {
                let parts: Option<Vec<String>> = items.iter().map(|it| self.array_literal(it, ty, file)).collect();
                Some(format!("{{{}}}", parts?.join(", ")))
            }
            other => self.literal(other, ty, file),
        }
    }

    /// The record constructor of a structure value (`EUInformation(unitId = 5066068, ...)`). Fields the value
    /// leaves out, or that do not fit their Modelica type, keep their defaults.
    fn record_literal(&mut self, dt: NodeIx, s: &Structure, file: FileId) -> Option<String> {
        self.depth += 1;
        if self.depth > 32 {
            self.depth -= 1;
            return None;
        }
        let info = self.record_info(dt);
        let class = self.datatype_path(dt);
        let mut args: Vec<String> = Vec::new();
        if let Some(DataTypeKind::OptionSet { .. }) = self.m.data_types.get(&dt).map(|i| &i.kind) {
            // An OptionSet structure value (Value/ValidBits as ByteStrings) is not decoded; the bits keep false.
            self.depth -= 1;
            return Some(format!("{class}()"));
        }
        if let Some(sw) = s.switch_field {
            args.push(format!("switchField = {sw}"));
        }
        for f in info.fields.iter() {
            let Some(field) = &f.field else { continue };
            let Some(v) = s.field(&f.name) else { continue };
            let ty = self.mtype(field.data_type);
            if matches!(ty, MType::Unmapped(_)) {
                continue;
            }
            let value = if field.value_rank >= 0 {
                let Variant::Array(_, items) = v else { continue };
                let items: Option<Vec<String>> = items.iter().map(|it| self.literal(it, &ty, file)).collect();
                // An empty array keeps the default: `{}` has no element type.
                let items = items.filter(|i| !i.is_empty());
                if let (Some(c), Some(i)) = (&f.count, &items) {
                    args.push(format!("{c} = {}", i.len()));
                }
                items.map(|i| format!("{{{}}}", i.join(", ")))
            } else {
                self.literal(v, &ty, file)
            };
            if let Some(v) = value {
                if let Some(flag) = &f.has_flag {
                    args.push(format!("{flag} = true"));
                }
                args.push(format!("{} = {v}", f.ident));
            }
        }
        self.depth -= 1;
        Some(format!("{class}({})", args.join(", ")))
    }

    /// The `type` of a built-in or simple DataType, a `record` of a structure or OptionSet, or the
    /// `enumeration` of an enumeration; `None` for a DataType that has no Modelica class (the ones mapped to a
    /// predefined type directly, and those without a faithful mapping).
    pub fn datatype_class(&mut self, dt: NodeIx) -> Option<(String, String)> {
        let m = self.m;
        let node = m.node(dt);
        let ns = node.id.ns;
        let names = self.names(ns);
        let ident = names.types.get(&dt)?.clone();
        let kind = m.data_types.get(&dt)?.kind.clone();
        let described = node.doc().map(text::html_paragraphs);
        let doc = described.clone().unwrap_or_else(|| super::ctx::undescribed(m, dt, "DataType"));
        let opcua = format!(
            "__OPCUA(nodeId={}, browseName={})",
            string_literal(&node_id_text(m, &node.id)),
            string_literal(&node.browse_name.name)
        );
        let desc = text::description(&node.browse_name.name, node.doc());
        let body = match kind {
            DataTypeKind::Builtin(b) => {
                let map = builtin_map(b).ok().filter(|m| m.alias)?;
                let attrs = attrs(map.min, map.max, map.unit);
                // The mapping says what the built-in type is; the nodeset may say more.
                let doc = format!("<p>{}.</p>{}", text::html_escape(map.doc), described.unwrap_or_default());
                format!(
                    "type {ident} = {}{attrs} {}\n  annotation (\n    {},\n    {opcua});\n",
                    map.base.name(),
                    string_literal(&format!("{}: {}", node.browse_name.name, map.doc)),
                    text::documentation(&doc)
                )
            }
            DataTypeKind::Simple(_) => {
                let sup = node.super_type?;
                let base = match self.mtype(sup) {
                    MType::Unmapped(_) => return None,
                    t => t.type_name().to_string(),
                };
                format!("type {ident} = {base} {desc}\n{}", annotation(&doc, &opcua))
            }
            DataTypeKind::Enumeration { values, .. } => {
                if values.is_empty() {
                    return None;
                }
                let lits = self.enum_literals(dt);
                let mut s = format!("type {ident} = enumeration(\n");
                for (i, (v, lit)) in lits.iter().enumerate() {
                    let mut d = format!("{} = {}", v.name, v.value);
                    if let Some(x) = v.description.as_deref().map(text::one_line).filter(|x| !x.is_empty()) {
                        d.push_str(": ");
                        d.push_str(&x);
                    }
                    s.push_str(&format!(
                        "    {lit} {}{}\n",
                        string_literal(&d),
                        if i + 1 < lits.len() { "," } else { ")" }
                    ));
                }
                let values: Vec<String> = lits.iter().map(|(v, _)| v.value.to_string()).collect();
                let vpath = format!("{}.EnumerationValues.{ident}", self.pkg[ns as usize]);
                let doc = format!(
                    "{doc}<p>The OPC UA value of a literal <code>x</code> is <code>{}[Integer(x)]</code>.</p>",
                    text::html_escape(&vpath)
                );
                s.push_str(&format!(
                    "  {desc}\n  annotation (\n    {},\n    __OPCUA(nodeId={}, browseName={}, values={{{}}}));\n",
                    text::documentation(&doc),
                    string_literal(&node_id_text(m, &node.id)),
                    string_literal(&node.browse_name.name),
                    values.join(", ")
                ));
                s
            }
            DataTypeKind::OptionSet { base, .. } => {
                let info = self.record_info(dt);
                let mut s = format!("record {ident} {desc}\n");
                for f in &info.fields {
                    let bit = f.bit.unwrap_or(0);
                    let d = match f.description.as_deref().map(text::one_line).filter(|x| !x.is_empty()) {
                        Some(x) => format!("{} (bit {bit}): {x}", f.name),
                        None => format!("{} (bit {bit})", f.name),
                    };
                    s.push_str(&format!("  Boolean {} = false {};\n", f.ident, string_literal(&d)));
                }
                let doc = format!(
                    "{doc}<p>An OptionSet of {}: one Boolean per defined bit, true when the bit is set. A record of \
                     Booleans rather than an Integer mask, because a Modelica Integer cannot hold the upper bits of \
                     a UInt32 or UInt64 mask and has no bit operators.</p>",
                    base.type_name()
                );
                s.push_str(&format!(
                    "  annotation (\n    {},\n    {},\n    {opcua});\nend {ident};\n",
                    text::documentation(&doc),
                    text::RECORD_ICON
                ));
                s
            }
            DataTypeKind::Structure { kind, has_definition, .. } => {
                if m.node(dt).id.ns0() == Some(ids::STRUCTURE) {
                    return None;
                }
                let info = self.record_info(dt);
                let mut s = format!("record {ident} {desc}\n");
                if let Some(sup) = info.extends {
                    s.push_str(&format!("  extends {};\n", self.datatype_path(sup)));
                }
                if kind == StructureKind::Union {
                    let alts: Vec<String> =
                        info.fields.iter().enumerate().map(|(i, f)| format!("{} = {}", i + 1, f.name)).collect();
                    s.push_str(&format!(
                        "  Integer switchField = 0 {};\n",
                        string_literal(&format!(
                            "SwitchField: which field holds the value (0 = none, {})",
                            alts.join(", ")
                        ))
                    ));
                }
                for f in info.fields.iter().filter(|f| !f.inherited) {
                    let Some(field) = &f.field else { continue };
                    let ty = self.mtype(field.data_type);
                    let fname = &f.name;
                    if let MType::Unmapped(why) = &ty {
                        s.push_str(&format!("  // Field {fname} is left out: {why}.\n"));
                        self.lossy(
                            dt,
                            format!(
                                "field `{fname}` of structure `{}` has no Modelica type and is left out: {why}",
                                m.qualified(dt)
                            ),
                        );
                        continue;
                    }
                    if let MType::Record { dt: fdt, .. } = &ty {
                        if *fdt == dt || self.record_contains(*fdt, dt, &mut BTreeSet::new()) {
                            s.push_str(&format!(
                                "  // Field {fname} is left out: its type {} contains {} again, and a Modelica record cannot contain itself.\n",
                                m.node(*fdt).browse_name.name,
                                m.node(dt).browse_name.name
                            ));
                            self.lossy(
                                dt,
                                format!(
                                    "field `{fname}` of structure `{}` is recursive and is left out",
                                    m.qualified(dt)
                                ),
                            );
                            continue;
                        }
                    }
                    if let Some(flag) = &f.has_flag {
                        s.push_str(&format!(
                            "  Boolean {flag} = false {};\n",
                            string_literal(&format!("Whether the optional field {fname} is set"))
                        ));
                    }
                    let dims = Self::dims(field.value_rank, &field.array_dimensions);
                    if let Some(c) = &f.count {
                        let default = self.default_literal(&ty);
                        s.push_str(&format!(
                            "  parameter Integer {c} = 0 {};\n",
                            string_literal(&format!("Number of elements of {fname}"))
                        ));
                        s.push_str(&format!(
                            "  {} {}[{c}] = fill({default}, {c}) {};\n",
                            ty.type_name(),
                            f.ident,
                            text::description(fname, field.description.as_deref())
                        ));
                        continue;
                    }
                    let (decl_dims, value) = match &dims {
                        Some(d) => (dims_text(d), self.default_array(&ty, d)),
                        None => (String::new(), self.default_literal(&ty)),
                    };
                    let mut d = field.description.clone();
                    if field.allow_sub_types && matches!(ty, MType::Record { .. }) {
                        let note = "subtypes are allowed by the nodeset; the record holds the fields of this type only";
                        d = Some(match d {
                            Some(x) => format!("{x} ({note})"),
                            None => format!("({note})"),
                        });
                    }
                    s.push_str(&format!(
                        "  {} {}{decl_dims} = {value} {};\n",
                        ty.type_name(),
                        f.ident,
                        text::description(fname, d.as_deref())
                    ));
                }
                let mut doc = doc;
                if !has_definition {
                    doc.push_str(
                        "<p>The nodeset gives no definition of this structure, so the record has no fields.</p>",
                    );
                }
                match kind {
                    StructureKind::StructureWithOptionalFields => doc.push_str(
                        "<p>A structure with optional fields: <code>has_&lt;field&gt;</code> says whether a field is set.</p>",
                    ),
                    StructureKind::Union => doc.push_str(
                        "<p>A union: <code>switchField</code> says which one of the fields holds the value.</p>",
                    ),
                    StructureKind::Structure => {}
                }
                let opcua = format!("{},\n    {opcua}", text::RECORD_ICON);
                s.push_str(&format!("{}end {ident};\n", annotation(&doc, &opcua)));
                s
            }
            DataTypeKind::AbstractBuiltin => return None,
        };
        Some((ident, body))
    }

    /// The `EnumerationValues` package of a namespace: one constant per emitted enumeration.
    pub fn enumeration_values(&mut self, ns: u16, enums: &[NodeIx]) -> String {
        let names = self.names(ns);
        let pkg = self.pkg[ns as usize].clone();
        let mut s = format!("package EnumerationValues \"OPC UA values of the enumerations of {pkg}.Types\"\n");
        for &dt in enums {
            let lits = self.enum_literals(dt);
            let values: Vec<String> = lits.iter().map(|(v, _)| v.value.to_string()).collect();
            let ident = &names.types[&dt];
            s.push_str(&format!(
                "  constant Integer {ident}[{}] = {{{}}}\n    {};\n",
                values.len(),
                values.join(", "),
                string_literal(&format!("OPC UA values of the literals of Types.{ident}, in their order"))
            ));
        }
        s.push_str(&format!(
            "  annotation (\n    {},\n    {});\nend EnumerationValues;\n",
            text::documentation(&format!(
                "<p>Modelica numbers the literals of an enumeration from 1; OPC UA gives each a value of its own, which \
                 need not start at 0 nor be consecutive. <code>EnumerationValues.E[Integer(x)]</code> is the OPC UA \
                 value of literal <code>x</code> of <code>{}.Types.E</code>.</p>",
                text::html_escape(&pkg)
            )),
            text::PACKAGE_ICON
        ));
        s
    }
}

/// The annotation of a class: its documentation (when there is any) and its origin.
fn annotation(doc_html: &str, opcua: &str) -> String {
    if doc_html.is_empty() {
        format!("  annotation (\n    {opcua});\n")
    } else {
        format!("  annotation (\n    {},\n    {opcua});\n", text::documentation(doc_html))
    }
}

/// `[3]`, `[:]`, `[2, 3]`.
pub fn dims_text(dims: &[Option<u32>]) -> String {
    let parts: Vec<String> = dims.iter().map(|d| d.map(|x| x.to_string()).unwrap_or_else(|| ":".into())).collect();
    format!("[{}]", parts.join(", "))
}

/// `(min=0, max=65535)`, or nothing.
pub fn attrs(min: Option<&str>, max: Option<&str>, unit: Option<&str>) -> String {
    let mut parts = Vec::new();
    if let Some(m) = min {
        parts.push(format!("min={m}"));
    }
    if let Some(m) = max {
        parts.push(format!("max={m}"));
    }
    if let Some(u) = unit {
        parts.push(format!("unit={}", string_literal(u)));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!("({})", parts.join(", "))
    }
}

pub fn as_i128(v: &Variant) -> Option<i128> {
    Some(match v {
        Variant::SByte(x) => *x as i128,
        Variant::Byte(x) => *x as i128,
        Variant::Int16(x) => *x as i128,
        Variant::UInt16(x) => *x as i128,
        Variant::Int32(x) => *x as i128,
        Variant::UInt32(x) => *x as i128,
        Variant::Int64(x) => *x as i128,
        Variant::UInt64(x) => *x as i128,
        Variant::StatusCode(x) => *x as i128,
        Variant::Variant(inner) => return as_i128(inner),
        _ => return None,
    })
}

fn qualified_name_text(ctx: &Ctx, q: &QualifiedName) -> String {
    if q.ns == 0 {
        q.name.clone()
    } else {
        format!("nsu={};{}", ctx.m.namespace_uri(q.ns), q.name)
    }
}
