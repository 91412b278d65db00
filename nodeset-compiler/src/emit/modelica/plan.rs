//! What planning produces: the plan of each class (its members, modifiers and equations) and what a planned class
//! offers to the classes built on it. `objects.rs` and `members.rs` plan, `mod.rs` renders.

use crate::model::{Field, NodeIx};
use crate::nodeid::QualifiedName;
use crate::value::BuiltinType;
use std::collections::BTreeSet;
use std::rc::Rc;

/// What a planned class offers to classes built on it.
#[derive(Debug, Clone)]
pub struct ClassInfo {
    pub key: ClassKey,
    pub elements: Vec<Element>,
    /// Every identifier the class uses (elements, `use_` flags, counts, state machine names).
    pub taken: BTreeSet<String>,
    /// Whether the class declares replaceable elements itself (not through `extends`); a redeclaration may
    /// only use a class with local replaceable elements when its constraining class has some too (MLS 6.4,
    /// as rumoca checks it).
    pub local_replaceable: bool,
    /// The state machine this class (or a base class) drives.
    pub state_machine: Option<Rc<SmInfo>>,
    /// The connectors on its icon.
    pub placed: Placed,
    /// The input connectors nothing binds, in the class itself and in its components (see [`Free`]).
    pub free: Rc<Vec<Free>>,
}

impl ClassInfo {
    /// Whether a component of the class leaves inputs unbound, so the class is partial and its components use
    /// its complete variant (`<Pkg>.Complete...`), which binds them to the nodeset's values.
    pub fn is_partial_by_inputs(&self) -> bool {
        self.free.iter().any(|f| f.path.len() > 1)
    }
}

/// An input connector nothing binds: a value the model publishes, which the physics that computes it
/// `connect`s to. The complete variant of a class binds it to the nodeset's value.
#[derive(Debug, Clone)]
pub struct Free {
    /// The component path, each step with whether that component is an array (`each` for what follows).
    pub path: Vec<(String, bool)>,
    /// The node whose value the complete variant binds.
    pub node: NodeIx,
    pub ty: MType,
}

impl Free {
    /// What a complete class binds the input to: the node's value.
    pub fn value(&self) -> Value {
        Value::Of { node: self.node, ty: self.ty.clone(), dims: None }
    }
}

#[derive(Debug, Clone)]
pub struct Element {
    pub bn: QualifiedName,
    pub ident: String,
    pub node: NodeIx,
    /// The reference from the parent (HasProperty, HasComponent, ...).
    pub rt: NodeIx,
    /// An optional element that a base class already made present (`final use_x = true`).
    pub present: bool,
    pub kind: ElemKind,
    pub use_flag: Option<String>,
    pub count: Option<String>,
    /// The replaceable class alias of an object (`replaceable model Axes = ...; Axes axes;`), which subclasses
    /// and users redeclare.
    pub alias: Option<String>,
    /// For a placeholder's array declared through an alias: where its pins are held ([`Pinned`]).
    pub pinned: Option<Pinned>,
    /// The free inputs of an object whose members this class modifies without a class of its own (else those of
    /// its class).
    pub nested_free: Option<Rc<Vec<Free>>>,
    /// The elements of an object's class as the modifiers on the component leave them, where a class modifies
    /// the members of the component without a class of its own (an optional member made present by
    /// `final use_x = true`, a value given), at any depth; else `None`, and those of its class hold. A class
    /// derived from this one overrides the members as they are here: it never sets the `final` flag twice.
    pub modified: Option<Rc<Vec<Element>>>,
}

/// A placeholder's array declared through an alias: its pins name aliases of the declaring class
/// ([`Item::PinAliases`]), which derived classes redeclare ([`Mod::Repin`]).
#[derive(Debug, Clone)]
pub struct Pinned {
    /// The class it was declared with.
    pub declared: ClassKey,
    /// The prefix of the declaring class's aliases that hold the pins: `<pin>_<A>` holds the choice for alias `A`
    /// ([`pin_alias`]). The alias's own name unless one of those names is taken.
    pub pin: String,
}

/// The alias of a declaring class that holds the pinned choice for alias `alias` of a component ([`Pinned::pin`]).
pub fn pin_alias(pin: &str, alias: &str) -> String {
    format!("{pin}_{alias}")
}

#[derive(Debug, Clone)]
pub enum ElemKind {
    Parameter {
        ty: MType,
        dims: Option<Vec<Option<u32>>>,
    },
    Signal {
        ty: MType,
        dims: Option<Vec<Option<u32>>>,
        /// An input connector nothing binds (see [`Free`]).
        free: bool,
    },
    Object {
        class: ClassKey,
    },
    Method,
    /// A child held by a reference that is not containment (Requires, Moves, ...), or whose containment would
    /// make the class contain itself: a `String` parameter with the NodeId of the target (an array of them for
    /// a placeholder).
    Reference {
        array: bool,
    },
    /// Declared nowhere (no Modelica type); the name stays taken.
    Skipped,
}

/// A class name in generated text: a fixed path or a class that is named once its owner is planned.
#[derive(Debug, Clone, PartialEq)]
pub enum TypeRef {
    Path(String),
    Class(ClassKey),
}

/// The value a declaration or modifier binds, as planning decides it; written as Modelica when the class is
/// rendered (`mod.rs`, `render_value`), so planning never turns the nodeset's values into text.
#[derive(Debug, Clone)]
pub enum Value {
    /// An expression the planning rule writes itself: a fixed literal (`0`, `true`), a NodeId string, or names
    /// (`fill("", nAxis)`).
    Text(String),
    /// What the nodeset gives `node`, in SI where it has an engineering unit, if it fits `ty` and `dims`; else
    /// the default of `ty` (of the array `dims`).
    Of {
        node: NodeIx,
        ty: MType,
        dims: Option<Vec<Option<u32>>>,
    },
    /// The default of `ty` repeated over `sizes` (counts' names or lengths): `fill(default, n, ...)`.
    Fill {
        ty: MType,
        sizes: Vec<String>,
    },
    /// The default of `ty`, `count` times, as a comprehension: `{default for i in 1:count}` (rumoca 0.10.2
    /// rejects `fill(R(), n)` of a record with a record field once n > 0: "expression shape mismatch").
    Each {
        ty: MType,
        count: String,
    },
}

impl From<&str> for Value {
    fn from(text: &str) -> Value {
        Value::Text(text.to_string())
    }
}

impl From<String> for Value {
    fn from(text: String) -> Value {
        Value::Text(text)
    }
}

#[derive(Debug, Clone)]
pub enum Mod {
    Value {
        ident: String,
        is_final: bool,
        attrs: Vec<String>,
        value: Option<Value>,
    },
    Nested {
        ident: String,
        mods: Vec<Mod>,
    },
    /// `redeclare model <Alias> = <class>`.
    Redeclare {
        ident: String,
        class: TypeRef,
    },
    /// On a component of `class`: the class's own choice for each of its replaceable aliases that some class
    /// redeclares, repeated as `redeclare model <Alias> = <class of Alias in class>` (see
    /// [`Ctx::redeclared`](super::ctx::Ctx::redeclared)). Equivalent Modelica; rumoca 0.10.2 needs it, because it
    /// lets an enclosing instance's redeclaration of an alias replace the nested class's own.
    Pin {
        class: ClassKey,
    },
    /// On a placeholder's array declared through an alias: [`Mod::Pin`], each choice named by an alias of the
    /// enclosing class, `redeclare model <A> = <pin>_<A>` ([`Pinned`], [`Item::PinAliases`]). pymoca 0.12.0 does
    /// not let a derived class override a declaration's redeclaration on an array sized by a parameter, so derived
    /// classes redeclare those aliases instead ([`Mod::Repin`]); rumoca reads the pin like [`Mod::Pin`].
    PinVia {
        pin: String,
        class: ClassKey,
    },
    /// In a derived class that redeclares the alias of component `ident` to `class`: `redeclare model
    /// <pin>_<A> = <class of A in class>` for each choice pinned where the component was declared
    /// (`declared`), and `ident(redeclare model <A> = ...)` for the choices only `class` has.
    Repin {
        ident: String,
        pin: String,
        class: ClassKey,
        declared: ClassKey,
    },
}

#[derive(Debug, Clone)]
pub enum Item {
    Comment(String),
    /// `replaceable model <ident> = <class> "desc";`
    Alias {
        ident: String,
        class: TypeRef,
        desc: String,
    },
    /// `replaceable model <pin>_<A> = <class of A in class>` for each choice a [`Mod::PinVia`] names, on the
    /// component declared through `alias`.
    PinAliases {
        alias: String,
        pin: String,
        class: ClassKey,
    },
    Decl {
        prefix: String,
        ty: TypeRef,
        ident: String,
        dims: String,
        mods: Vec<Mod>,
        value: Option<Value>,
        cond: Option<String>,
        desc: String,
        annotation: String,
    },
}

/// A class ready to be written.
#[derive(Debug, Clone)]
pub struct ClassPlan {
    pub keyword: &'static str,
    pub desc: String,
    pub doc_html: String,
    pub extends: Option<(TypeRef, Vec<Mod>)>,
    pub items: Vec<Item>,
    pub equations: Vec<String>,
    pub opcua: String,
}

/// The classes of one owner (an ObjectType or a top-level instance).
#[derive(Debug, Default)]
pub struct OwnerPlan {
    pub main: Option<ClassPlan>,
    pub decls: Vec<(String, ClassPlan)>,
}

/// A child of the node a class is planned for, with the reference that holds it.
#[derive(Debug, Clone, Copy)]
pub struct Own {
    pub node: NodeIx,
    pub rt: NodeIx,
}

/// A declaration class whose base is a type still being planned (types that contain each other through
/// placeholders); planned as soon as that type is complete.
#[derive(Debug, Clone)]
pub struct Deferred {
    pub owner: Owner,
    pub path: String,
    pub node: NodeIx,
    pub td: NodeIx,
    pub children: Vec<Own>,
    pub mode: Mode,
}

/// What planning a class body produced.
#[derive(Debug, Default)]
pub struct Body {
    pub mods: Vec<Mod>,
    pub items: Vec<Item>,
    pub equations: Vec<String>,
    pub elements: Vec<Element>,
    pub taken: BTreeSet<String>,
    pub local_replaceable: bool,
    /// The body declares or redeclares something, so it needs a class of its own (modifiers alone do not).
    pub adds: bool,
    /// The state the inherited state machine starts in here, when a child CurrentState names another one.
    pub initial: Option<usize>,
    /// How many input and output connectors the class has placed on its icon (inherited ones included).
    pub placed: Placed,
}

/// How many input connectors (left edge of the icon) and output connectors (right edge) a class places.
#[derive(Debug, Clone, Copy, Default)]
pub struct Placed {
    pub inputs: usize,
    pub outputs: usize,
}

impl Placed {
    /// The `Placement` of the next input (or output) connector: inputs down the left edge of the icon,
    /// outputs down the right one, 20 units apart from the top, as in the Modelica Standard Library's blocks.
    pub fn next(&mut self, input: bool) -> String {
        let i = if input { &mut self.inputs } else { &mut self.outputs };
        let y = 80 - 20 * *i as i64;
        *i += 1;
        let (x0, x1) = if input { (-120, -100) } else { (100, 120) };
        format!("Placement(transformation(extent={{{{{x0},{}}},{{{x1},{}}}}}))", y - 10, y + 10)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// An ObjectType or the class of an instance declaration: children without a ModellingRule are not
    /// instantiated.
    Type,
    /// An instance: every child is part of it, optional members are present when a child is.
    Instance,
}

/// Who owns a set of instance-declaration classes: an ObjectType or a top-level instance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Owner {
    Type(NodeIx),
    Instance(NodeIx),
}

impl Owner {
    pub fn node(self) -> NodeIx {
        match self {
            Owner::Type(ix) | Owner::Instance(ix) => ix,
        }
    }
}

/// A generated class, before it has a Modelica name.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ClassKey {
    /// The class of an ObjectType (`<Pkg>.ObjectTypes.<Name>`).
    Type(NodeIx),
    /// The class of an instance declaration that adds to its type, by its browse path below the owner.
    Decl(Owner, String),
}

/// The state machine a class drives: the names its subclasses reuse.
#[derive(Debug, Clone)]
pub struct SmInfo {
    pub level: u32,
    pub level_param: String,
    pub var: String,
    /// State node -> constant.
    pub states: Vec<(NodeIx, String)>,
    /// The StateNumber of each state (the nodeset's, or the one given here), in the order of `states`.
    pub numbers: Vec<u32>,
    /// The index in `states` of the state the machine starts in.
    pub initial: usize,
    /// The `CurrentState` component, and the variable its final binding reads (the DisplayName of the current
    /// state, set by an equation of the level that drives the machine); `None` when the class has no String
    /// CurrentState.
    pub text: Option<(String, String)>,
    /// Cause (method or transition) node -> trigger input.
    pub triggers: Vec<(NodeIx, String)>,
    /// The BrowseNames of the states and transitions covered.
    pub nodes: BTreeSet<QualifiedName>,
}

/// The predefined Modelica type a mapped OPC UA type is built on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Base {
    Real,
    Integer,
    Boolean,
    String,
}

impl Base {
    pub fn name(self) -> &'static str {
        match self {
            Base::Real => "Real",
            Base::Integer => "Integer",
            Base::Boolean => "Boolean",
            Base::String => "String",
        }
    }
}

/// The Modelica form of an OPC UA DataType.
#[derive(Clone, Debug, PartialEq)]
pub enum MType {
    /// A predefined type, directly or through a `type` of a Types package (`class`), with the attributes the
    /// alias carries (so connectors, which are declared on the predefined type, can repeat them).
    Scalar {
        base: Base,
        class: Option<String>,
        min: Option<&'static str>,
        max: Option<&'static str>,
        unit: Option<&'static str>,
        builtin: BuiltinType,
    },
    Enum {
        class: String,
        dt: NodeIx,
    },
    Record {
        class: String,
        dt: NodeIx,
    },
    /// No faithful mapping; the reason, for the comment that replaces the declaration.
    Unmapped(String),
}

impl MType {
    /// The type name used in declarations of parameters and record fields.
    pub fn type_name(&self) -> &str {
        match self {
            MType::Scalar { base, class, .. } => class.as_deref().unwrap_or(base.name()),
            MType::Enum { class, .. } | MType::Record { class, .. } => class,
            MType::Unmapped(_) => "",
        }
    }
}

/// Field names of a structure (or bits of an OptionSet), inherited ones included.
#[derive(Debug)]
pub struct RecordInfo {
    pub fields: Vec<RecField>,
    pub taken: BTreeSet<String>,
    /// The structure this record `extends` (a supertype with fields of its own).
    pub extends: Option<NodeIx>,
}

#[derive(Debug, Clone)]
pub struct RecField {
    pub name: String,
    pub ident: String,
    /// `has_<ident>` of an optional field.
    pub has_flag: Option<String>,
    /// `n<Ident>`, the length of an array of records of unknown length (which needs a size).
    pub count: Option<String>,
    pub field: Option<Field>,
    pub bit: Option<i64>,
    pub description: Option<String>,
    /// Declared by a supertype (and inherited through `extends`).
    pub inherited: bool,
}
