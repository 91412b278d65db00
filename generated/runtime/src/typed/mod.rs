//! The typed API generated handles are built on: Rust value types for OPC UA DataTypes ([`UaValue`]),
//! handles to the nodes of an instance ([`Variable<T>`], [`Method<I, O>`], [`ObjectNode`],
//! [`Placeholders<H>`]), instantiation of types as they prescribe ([`Instantiate`]), and the traits that
//! generated code implements for every ObjectType ([`ObjectType`]), and the member markers that
//! `nodeset-derive` checks bindings against ([`VariableMember`]).

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
use crate::NsNodeId;

/// A generated handle of an ObjectType: its instances can be created ([`ObjectType::instantiate`]) and bound
/// ([`ModelManager::bind`]).
#[diagnostic::on_unimplemented(
    message = "`{Self}` is not an ObjectType handle",
    label = "name a struct of a generated `objects` module that stands for an ObjectType",
    note = "generated ObjectType handles are in `models::<namespace>::objects`; VariableTypes and data types cannot be bound"
)]
pub trait ObjectType: Handle {
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

/// A generated handle of a VariableType.
pub trait VariableType: Handle {
    /// The VariableType's NodeId.
    const TYPE_ID: NsNodeId;
    /// The VariableType's BrowseName.
    const BROWSE_NAME: &'static str;
}

/// A variable reachable from an instance of an ObjectType (without crossing a placeholder), as generated
/// code declares it: one `const` per browse path in `<type module>::members::<Owner>`, named from the path
/// (`ParameterSet__ActualPosition`). `nodeset-derive` names these to check a binding at compile time: the
/// field's type against `S` (through [`Holds`]), its ValueRank against `value_rank`, and the mandatory
/// variables against the module's `REQUIRED`.
///
/// A marker is a value, not a type with trait impls: a namespace has about a thousand of them, and one
/// constant each is what the compiler checks fastest.
pub struct VariableMember<S> {
    /// BrowseNames from the instance down to the variable, each with its namespace URI.
    pub path: &'static [(&'static str, &'static str)],
    /// The variable's ValueRank.
    pub value_rank: i32,
    /// Whether every instance has it (Mandatory, all the way down).
    pub mandatory: bool,
    /// Whether the nodeset gives the declaration an initial value.
    pub has_default: bool,
    /// Whether clients may write it (CurrentWrite in its AccessLevel).
    pub writable: bool,
    /// `S`: the Rust type of one value of the variable's DataType. (Public so that a marker is a struct
    /// literal: its `path` is then a `'static` slice in place, which a `const fn` argument would not be.)
    pub scalar: PhantomData<fn() -> S>,
}

impl<S> VariableMember<S> {
    /// Compiles only if a field of type `F` holds this variable's values (`nodeset-derive` calls it for
    /// each bound field). A method, so that `S` is the marker's and only `F` is named: the check is then
    /// `F: Holds<S>` with both known, and fails with [`Holds`]'s message.
    pub fn holds<F: Holds<S>>(&self) {}
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
/// a marker declared here shadows the supertype's of that name), with, for each variable member declared
/// here, a [`VariableMember`] constant given the marker name,
/// the Rust scalar type, the ValueRank, the browse path as (index into `NS`, name) pairs, and whether it
/// is mandatory, has a default value, and is writable; and `REQUIRED`, the mandatory variables without a
/// default, with the message for a derive that leaves one unbound.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_object_members {
    ($owner:ident $(: $base:path)?; required: [$(($rp:literal, $rm:literal)),* $(,)?]; $($m:ident: $scalar:ty, $rank:literal, [$($k:literal $name:literal),*], $mandatory:literal $default:literal $writable:literal;)*) => {
        #[doc = concat!(" Member markers of [`", stringify!($owner), "`](super::", stringify!($owner), ") for `nodeset-derive`.")]
        #[allow(non_upper_case_globals)]
        pub mod $owner {
            #[allow(unused_imports)]
            use super::super::{t, ua};
            $(
                #[doc(no_inline)]
                pub use $base::*;
            )?
            $(
                #[doc = concat!(" The variable `", $($name, "/",)* "`.")]
                pub const $m: $crate::typed::VariableMember<$scalar> = $crate::typed::VariableMember {
                    path: &[$((super::super::NS[$k], $name)),*],
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

/// The [`ObjectType`] impl of a generated handle.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_object_type {
    ($t:ident, $id:expr, $name:literal) => {
        impl $crate::typed::ObjectType for $t {
            const TYPE_ID: $crate::NsNodeId = $id;
            const BROWSE_NAME: &'static str = $name;
        }
    };
}
pub use crate::__nodeset_object_type as object_type;

/// The [`VariableType`] impl of a generated handle.
#[doc(hidden)]
#[macro_export]
macro_rules! __nodeset_variable_type {
    ($t:ident, $id:expr, $name:literal) => {
        impl $crate::typed::VariableType for $t {
            const TYPE_ID: $crate::NsNodeId = $id;
            const BROWSE_NAME: &'static str = $name;
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
