//! The typed API generated handles are built on: Rust value types for OPC UA DataTypes ([`UaValue`]),
//! handles to the nodes of an instance ([`Variable<T>`], [`Method<I, O>`], [`ObjectNode`],
//! [`Placeholders<H>`]), instantiation of types as they prescribe ([`Instantiate`]), and the traits that
//! generated code implements for every ObjectType ([`ObjectType`]) and VariableType ([`VariableType`]), both
//! [`TypeHandle`]s, and the member markers that `nodeset-derive` checks bindings against and typed clients
//! read ([`VariableMember`], [`MethodMember`]).

mod defaults;
pub mod handle;
pub mod instance;
pub mod model;
pub mod program;
pub mod value;

pub use handle::{Arguments, BindError, Binder, CallContext, Handle, Method, ObjectNode, Placeholders, Variable};
pub use instance::{Instantiate, InstantiateError};
pub use model::{Bound, ObjectModel};
pub use program::{
    Control, Machine, ParameterValue, Parameters, Program, ProgramError, ProgramState, ProgramType, StateMachine,
    StateRow, StateTable, TransitionEvent, TransitionRow,
};
pub use crate::__nodeset_parameters as parameters;
pub use crate::__nodeset_program_type as program_type;
pub use value::{UaStruct, UaValue};

use std::marker::PhantomData;

use opcua::types::{NodeId, QualifiedName};

use crate::server::ModelManager;
use crate::table::NsNodeId;

/// What the handles of ObjectTypes and VariableTypes have in common: the type whose instances they stand
/// for. A typed client binds a remote instance as `H` (`client::Remote<H>`) when its TypeDefinition is
/// this type or a subtype of it.
///
/// Its constants repeat [`ObjectType`]'s or [`VariableType`]'s under other names, so that a bound on both
/// traits (every [`ObjectType`] is a `TypeHandle`) does not make `H::TYPE_ID` ambiguous, and code that names
/// `AxisType::TYPE_ID` with `ObjectType` in scope keeps working. The generated `object_type!` and
/// `variable_type!` invocations implement it.
#[diagnostic::on_unimplemented(
    message = "`{Self}` is not the handle of an ObjectType or VariableType",
    label = "name a struct of a generated `objects` module",
    note = "generated ObjectType and VariableType handles are in `models::<namespace>::objects`; data types cannot be bound"
)]
pub trait TypeHandle: Handle {
    /// The type's NodeId.
    const TYPE_NODE_ID: NsNodeId;
    /// The type's BrowseName (its name; the namespace is `TYPE_NODE_ID`'s).
    const TYPE_NAME: &'static str;
}

/// A generated handle of an ObjectType: its instances can be created ([`ObjectType::instantiate`]) and bound
/// ([`ModelManager::bind`]).
#[diagnostic::on_unimplemented(
    message = "`{Self}` is not an ObjectType handle",
    label = "name a struct of a generated `objects` module that stands for an ObjectType",
    note = "generated ObjectType handles are in `models::<namespace>::objects`; VariableTypes and data types cannot be bound"
)]
pub trait ObjectType: TypeHandle {
    /// The ObjectType's NodeId.
    const TYPE_ID: NsNodeId;
    /// The ObjectType's BrowseName (its name; the namespace is `TYPE_ID`'s).
    const BROWSE_NAME: &'static str;

    /// Creates an instance named `name` under `parent` (mandatory members, and what `options` asks for) and
    /// binds a handle to it. Its BrowseName is in the server's instance namespace.
    fn instantiate(manager: &ModelManager, parent: &NodeId, name: &str, options: &Instantiate) -> Result<Self, InstantiateError> {
        let type_id = manager.resolve(Self::TYPE_ID).ok_or(InstantiateError::Bind(BindError::UnknownNamespace(
            Self::TYPE_ID.namespace_uri.to_owned(),
        )))?;
        let browse_name = QualifiedName::new(manager.instance_namespace(), name);
        let id = manager.instantiate(&type_id, parent, browse_name, options)?;
        Ok(manager.bind(&id)?)
    }
}

/// A generated handle of a VariableType. Its instance's own value is a [`Variable<Self::Value>`] (the
/// handle's `node`), and its child variables have markers in `members::<Type>` like an ObjectType's.
pub trait VariableType: TypeHandle {
    /// The VariableType's NodeId.
    const TYPE_ID: NsNodeId;
    /// The VariableType's BrowseName.
    const BROWSE_NAME: &'static str;
    /// The Rust type of the variable's value, from the VariableType's DataType and ValueRank: the scalar
    /// type for ValueRank -1 (the default), `Vec` of it for 0 and 1, and [`opcua::types::Variant`] for
    /// other ranks and for a DataType without a Rust type of its own (abstract ones such as `Number` or
    /// `BaseDataType`). An instance of a subtype may narrow the DataType; its value is still read as this.
    type Value: UaValue;
}

/// A variable reachable from an instance of an ObjectType (without crossing a placeholder), as generated
/// code declares it: one `const` per browse path in `<type module>::members::<Owner>`, named from the path
/// (`ParameterSet__ActualPosition`). `nodeset-derive` names these to check a binding at compile time: the
/// field's type against `S` (through [`Holds`]), its ValueRank against `value_rank`, and the mandatory
/// variables against the module's `REQUIRED`.
///
/// A marker is a value, not a type with trait impls: a namespace has about a thousand of them, and one
/// constant each is what the compiler checks fastest. Its browse path is one string (see [`MemberPath`]):
/// a constant of scalars and string literals costs rustc a fraction of one holding a slice of pairs.
pub struct VariableMember<S> {
    /// The namespace URIs that `path`'s indices refer to (the generated module's `NS`).
    pub ns: &'static [&'static str],
    /// The BrowseNames from the instance down to the variable, in [`MemberPath`]'s text form.
    pub path: &'static str,
    /// The variable's ValueRank.
    pub value_rank: i32,
    /// Whether every instance has it (Mandatory, all the way down).
    pub mandatory: bool,
    /// Whether the nodeset gives the declaration an initial value.
    pub has_default: bool,
    /// Whether clients may write it (CurrentWrite in its AccessLevel).
    pub writable: bool,
    /// `S`: the Rust type of one value of the variable's DataType. (Public so that a marker is a struct
    /// literal, which rustc checks faster than a `const fn` call.)
    pub scalar: PhantomData<fn() -> S>,
}

/// A method reachable from an instance of an ObjectType (without crossing a placeholder), as generated code
/// declares it beside the [`VariableMember`]s: one `const` per browse path in `<type module>::members::<Owner>`
/// (`Lock__InitLock`), whose type carries the method's input and output tuples (`I`, `O`, from its
/// InputArguments and OutputArguments, as [`Method<I, O>`] has them on the server). A typed client calls it:
/// `remote.call(&members::MotionDeviceType::Lock__InitLock, ("cell".to_owned(),))` is an `(i32,)`.
pub struct MethodMember<I, O> {
    /// The namespace URIs that `path`'s indices refer to (the generated module's `NS`).
    pub ns: &'static [&'static str],
    /// The BrowseNames from the instance down to the method, in [`MemberPath`]'s text form; the method is
    /// called on the object the path leads to before its last segment (the instance if there is none).
    pub path: &'static str,
    /// Whether every instance has it (Mandatory, all the way down).
    pub mandatory: bool,
    /// The signature. (Public so that a marker is a struct literal.)
    pub signature: PhantomData<fn(I) -> O>,
}

impl<I, O> MethodMember<I, O> {
    /// The marker's browse path.
    pub const fn browse_path(&self) -> MemberPath {
        MemberPath { ns: self.ns, text: self.path }
    }
}

impl<I, O> std::fmt::Debug for MethodMember<I, O> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MethodMember")
            .field("path", &self.path)
            .field("inputs", &std::any::type_name::<I>())
            .field("outputs", &std::any::type_name::<O>())
            .field("mandatory", &self.mandatory)
            .finish()
    }
}

/// A browse path as generated code writes it: each BrowseName as `index:name`, where `index` is a position
/// in `ns` (the namespace URIs of the generated module), joined by `/`; a `/` or `\` in a name is escaped
/// with `\`. With `ns = ["…/Robotics/", "…/DI/"]`, `1:ParameterSet/0:ActualPosition` is DI's
/// `ParameterSet`, then Robotics' `ActualPosition`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemberPath {
    /// The namespace URIs the indices refer to.
    pub ns: &'static [&'static str],
    /// The path text.
    pub text: &'static str,
}

/// A [`MemberPath`] whose text does not follow the format.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BadMemberPath {
    /// The path text.
    pub text: &'static str,
    /// What is wrong.
    pub reason: String,
}

impl std::fmt::Display for BadMemberPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "member path `{}`: {}", self.text, self.reason)
    }
}

impl std::error::Error for BadMemberPath {}

impl MemberPath {
    /// The path without its last segment (`None` for a path of one segment): the object that holds a
    /// method. An escaped `/` does not end a segment.
    pub fn parent(&self) -> Option<MemberPath> {
        let mut last = None;
        let mut escaped = false;
        for (i, c) in self.text.char_indices() {
            match c {
                _ if escaped => escaped = false,
                '\\' => escaped = true,
                '/' => last = Some(i),
                _ => {}
            }
        }
        last.map(|i| MemberPath { ns: self.ns, text: &self.text[..i] })
    }

    /// The BrowseNames along the path, each with its namespace URI.
    pub fn segments(&self) -> Result<Vec<(&'static str, String)>, BadMemberPath> {
        let bad = |reason: String| BadMemberPath { text: self.text, reason };
        let mut out = Vec::new();
        if self.text.is_empty() {
            return Err(bad("the path is empty".into()));
        }
        let mut rest = self.text;
        loop {
            let (index, after) = rest.split_once(':').ok_or_else(|| bad(format!("segment {} has no `index:`", out.len() + 1)))?;
            let index: usize = index.parse().map_err(|_| bad(format!("segment {}: `{index}` is not an index", out.len() + 1)))?;
            let uri = *self.ns.get(index).ok_or_else(|| {
                bad(format!("segment {}: namespace index {index}, but there are {} URIs", out.len() + 1, self.ns.len()))
            })?;
            let mut name = String::new();
            let mut chars = after.char_indices();
            let mut next = None;
            while let Some((i, c)) = chars.next() {
                match c {
                    '\\' => match chars.next() {
                        Some((_, e @ ('/' | '\\'))) => name.push(e),
                        _ => return Err(bad(format!("segment {}: `\\` escapes only `/` and `\\`", out.len() + 1))),
                    },
                    '/' => {
                        next = Some(&after[i + 1..]);
                        break;
                    }
                    c => name.push(c),
                }
            }
            out.push((uri, name));
            match next {
                Some(r) => rest = r,
                None => return Ok(out),
            }
        }
    }
}

impl<S> VariableMember<S> {
    /// Compiles only if a field of type `F` holds this variable's values (`nodeset-derive` calls it for
    /// each bound field). A method, so that `S` is the marker's and only `F` is named: the check is then
    /// `F: Holds<S>` with both known, and fails with [`Holds`]'s message.
    pub fn holds<F: Holds<S>>(&self) {}

    /// The marker's browse path.
    pub const fn browse_path(&self) -> MemberPath {
        MemberPath { ns: self.ns, text: self.path }
    }
}

impl<S> std::fmt::Debug for VariableMember<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VariableMember")
            .field("path", &self.path)
            .field("scalar", &std::any::type_name::<S>())
            .field("value_rank", &self.value_rank)
            .field("mandatory", &self.mandatory)
            .field("has_default", &self.has_default)
            .field("writable", &self.writable)
            .finish()
    }
}

/// Checks, for `nodeset-derive`, that a field's Rust type holds the values of a variable member: the same
/// scalar type. (The ValueRank is checked separately, with [`value::rank_fits`].)
#[diagnostic::on_unimplemented(
    message = "the field's type `{Self}` does not hold values of this variable's DataType (`{S}`)",
    label = "expected `{S}` (or `Vec<{S}>` for an array)"
)]
pub trait Holds<S> {}

impl<S: UaValue<Scalar = S>> Holds<S> for S {}
impl<S: UaValue<Scalar = S>> Holds<S> for Vec<S> {}
impl Holds<String> for opcua::types::UAString {}

/// Implements [`UaValue`] for a generated enumeration (`#[repr(i32)]`, with `TryFrom<i32>`).
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_ua_enum {
    ($($t:ty),* $(,)?) => {$(
        impl $crate::typed::UaValue for $t {
            type Scalar = $t;
            const VALUE_RANK: i32 = -1;
            const VARIANT_TYPE: opcua::types::VariantScalarTypeId = opcua::types::VariantScalarTypeId::Int32;
            fn to_variant(&self) -> opcua::types::Variant {
                opcua::types::Variant::Int32(*self as i32)
            }
            fn from_variant(value: &opcua::types::Variant) -> Option<Self> {
                let i = $crate::typed::value::enum_value(value)?;
                <$t>::try_from(i32::try_from(i).ok()?).ok()
            }
        }
    )*};
}
pub use crate::__nodeset_ua_enum as ua_enum;

/// Implements [`UaValue`] for a generated OptionSet (bit flags over an unsigned integer).
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_ua_option_set {
    ($t:ty, $bits:ty, $variant:ident) => {
        impl $crate::typed::UaValue for $t {
            type Scalar = $t;
            const VALUE_RANK: i32 = -1;
            const VARIANT_TYPE: opcua::types::VariantScalarTypeId = opcua::types::VariantScalarTypeId::$variant;
            fn to_variant(&self) -> opcua::types::Variant {
                opcua::types::Variant::$variant(self.bits())
            }
            fn from_variant(value: &opcua::types::Variant) -> Option<Self> {
                let bits = $crate::typed::value::option_set_bits(value)?;
                Some(<$t>::from_bits_retain(<$bits>::try_from(bits).ok()?))
            }
        }
    };
}
pub use crate::__nodeset_ua_option_set as ua_option_set;

/// Marks generated structures as [`UaStruct`]s.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_ua_struct {
    ($($t:ty),* $(,)?) => {$( impl $crate::typed::UaStruct for $t {} )*};
}
pub use crate::__nodeset_ua_struct as ua_struct;

/// Declares the member markers of an ObjectType (generated `members` modules use it): a module named
/// after the handle that re-exports the markers of its supertype's module when one is given (`Owner: path;`;
/// a marker declared here shadows the supertype's of that name), with, for each method member declared here
/// (`methods: [Name: (Inputs) => (Outputs), "path", mandatory;]`), a [`MethodMember`]; for each variable
/// member declared here, a [`VariableMember`] constant given the marker name, the Rust scalar type, the
/// ValueRank, the browse path (a [`MemberPath`] text over the `NS` of the module two levels up), and whether
/// it is mandatory, has a default value, and is writable; and `REQUIRED`, the mandatory variables without a
/// default, with the message for a derive that leaves one unbound.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_object_members {
    (
        $owner:ident $(: $base:path)?;
        $(methods: [$($fm:ident: $fi:ty => $fo:ty, $fpath:literal, $fmandatory:literal;)*];)?
        required: [$(($rp:literal, $rm:literal)),* $(,)?];
        $($m:ident: $scalar:ty, $rank:literal, $path:literal, $mandatory:literal $default:literal $writable:literal;)*
    ) => {
        #[doc = concat!(" Member markers of [`", stringify!($owner), "`](super::", stringify!($owner), ") for `nodeset-derive`.")]
        #[allow(non_upper_case_globals)]
        pub mod $owner {
            #[allow(unused_imports)]
            use super::super::{t, ua};
            $(
                #[doc(no_inline)]
                pub use $base::*;
            )?
            $($(
                #[doc = concat!(" The method `", $fpath, "`.")]
                pub const $fm: $crate::typed::MethodMember<$fi, $fo> = $crate::typed::MethodMember {
                    ns: super::super::NS,
                    path: $fpath,
                    mandatory: $fmandatory,
                    signature: ::core::marker::PhantomData,
                };
            )*)?
            $(
                #[doc = concat!(" The variable `", $path, "`.")]
                pub const $m: $crate::typed::VariableMember<$scalar> = $crate::typed::VariableMember {
                    ns: super::super::NS,
                    path: $path,
                    value_rank: $rank,
                    mandatory: $mandatory,
                    has_default: $default,
                    writable: $writable,
                    scalar: ::core::marker::PhantomData,
                };
            )*
            /// Mandatory variables without a default value, with the message for an unbound one.
            pub const REQUIRED: &[(&str, &str)] = &[$(($rp, $rm)),*];
        }
    };
}
pub use crate::__nodeset_object_members as object_members;
/// The member markers of a VariableType (its child variables, such as AnalogItemType's `EURange`): the
/// same declaration as [`object_members!`].
pub use crate::__nodeset_object_members as variable_members;

/// `Debug` of a generated handle: its name and node, not the whole tree of members (which a derive would
/// print, and compile a `Debug` of every member type for).
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_debug_handle {
    ($t:ident) => {
        impl ::std::fmt::Debug for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                $crate::typed::fmt_handle(f, stringify!($t), &self.node)
            }
        }
    };
}
pub use crate::__nodeset_debug_handle as debug_handle;

/// What [`debug_handle!`] prints: `Name { node: .., .. }`.
#[doc(hidden)]
pub fn fmt_handle(f: &mut std::fmt::Formatter<'_>, name: &str, node: &dyn std::fmt::Debug) -> std::fmt::Result {
    f.debug_struct(name).field("node", node).finish_non_exhaustive()
}

/// `Deref` from a generated handle to the handle of its supertype.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_deref_base {
    ($t:ident => $base:ty) => {
        impl std::ops::Deref for $t {
            type Target = $base;
            fn deref(&self) -> &$base {
                &self.base
            }
        }
    };
}
pub use crate::__nodeset_deref_base as deref_base;

/// The [`ObjectType`] and [`TypeHandle`] impls of a generated handle.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_object_type {
    ($t:ident, $id:expr, $name:literal) => {
        impl $crate::typed::TypeHandle for $t {
            const TYPE_NODE_ID: $crate::table::NsNodeId = $id;
            const TYPE_NAME: &'static str = $name;
        }
        impl $crate::typed::ObjectType for $t {
            const TYPE_ID: $crate::table::NsNodeId = $id;
            const BROWSE_NAME: &'static str = $name;
        }
    };
}
pub use crate::__nodeset_object_type as object_type;

/// The [`VariableType`] and [`TypeHandle`] impls of a generated handle, with the Rust type of its value.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_variable_type {
    ($t:ident, $id:expr, $name:literal, $value:ty) => {
        impl $crate::typed::TypeHandle for $t {
            const TYPE_NODE_ID: $crate::table::NsNodeId = $id;
            const TYPE_NAME: &'static str = $name;
        }
        impl $crate::typed::VariableType for $t {
            const TYPE_ID: $crate::table::NsNodeId = $id;
            const BROWSE_NAME: &'static str = $name;
            type Value = $value;
        }
    };
}
pub use crate::__nodeset_variable_type as variable_type;

ua_struct!(
    opcua::types::Argument,
    opcua::types::AxisInformation,
    opcua::types::BuildInfo,
    opcua::types::ComplexNumberType,
    opcua::types::DoubleComplexNumberType,
    opcua::types::EUInformation,
    opcua::types::EnumValueType,
    opcua::types::KeyValuePair,
    opcua::types::Range,
    opcua::types::RationalNumber,
    opcua::types::ServerStatusDataType,
    opcua::types::ThreeDCartesianCoordinates,
    opcua::types::ThreeDFrame,
    opcua::types::ThreeDOrientation,
    opcua::types::ThreeDVector,
    opcua::types::TimeZoneDataType,
    opcua::types::XVType,
);

#[cfg(test)]
mod tests {
    use super::{BadMemberPath, MemberPath};

    const NS: &[&str] = &["urn:a", "urn:b"];

    fn segments(text: &'static str) -> Result<Vec<(&'static str, String)>, BadMemberPath> {
        MemberPath { ns: NS, text }.segments()
    }

    #[test]
    fn member_paths_decode_with_their_namespaces() {
        assert_eq!(segments("0:Manufacturer").unwrap(), [("urn:a", "Manufacturer".to_string())]);
        assert_eq!(
            segments("1:ParameterSet/0:ActualPosition").unwrap(),
            [("urn:b", "ParameterSet".to_string()), ("urn:a", "ActualPosition".to_string())]
        );
        // A name may hold `:` (only the first one ends the index), and escaped `/` and `\`.
        assert_eq!(
            segments(r"0:a:b\/c\\d/1:<Axis>").unwrap(),
            [("urn:a", r"a:b/c\d".to_string()), ("urn:b", "<Axis>".to_string())]
        );
        assert_eq!(segments("1:").unwrap(), [("urn:b", String::new())]);
    }

    #[test]
    fn the_parent_of_a_member_path_ends_before_its_last_unescaped_slash() {
        let parent = |text: &'static str| MemberPath { ns: NS, text }.parent().map(|p| p.text);
        assert_eq!(parent("1:Lock/1:InitLock"), Some("1:Lock"));
        assert_eq!(parent("0:A/0:B/1:C"), Some("0:A/0:B"));
        assert_eq!(parent(r"0:A\/B/1:C\/D"), Some(r"0:A\/B"));
        assert_eq!(parent(r"0:A\\/1:C"), Some(r"0:A\\"));
        assert_eq!(parent(r"0:A\/B"), None);
        assert_eq!(parent("0:Start"), None);
    }

    #[test]
    fn bad_member_paths_say_what_is_wrong() {
        let reason = |text| segments(text).unwrap_err().reason;
        assert_eq!(reason(""), "the path is empty");
        assert_eq!(reason("Manufacturer"), "segment 1 has no `index:`");
        assert_eq!(reason("0:A/x:B"), "segment 2: `x` is not an index");
        assert_eq!(reason("0:A/2:B"), "segment 2: namespace index 2, but there are 2 URIs");
        assert_eq!(reason(r"0:A\n"), r"segment 1: `\` escapes only `/` and `\`");
        assert_eq!(reason("0:A\\"), r"segment 1: `\` escapes only `/` and `\`");
        assert_eq!(
            segments("0:A/").unwrap_err().to_string(),
            "member path `0:A/`: segment 2 has no `index:`"
        );
    }
}
