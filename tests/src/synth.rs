//! Synthetic NodeSet2 files: valid models that require only the base namespace, made as large or as oddly
//! shaped as a resource test or the scale bench (`cargo xtask bench --scenario scale`) needs. Nothing made
//! here is committed; the tests write it to temporary folders.

use std::fmt::Write;

/// The namespace of every synthetic model.
pub const URI: &str = "http://example.com/synth/";

/// How the nodes of a synthetic model hang together.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// One object with `n` variables (each with a value) as its components.
    Siblings,
    /// `n` objects, each a component of the one before: a hierarchy `n` levels deep.
    DeepInstances,
    /// `n` ObjectTypes, each a subtype of the one before.
    DeepTypes,
    /// `n` objects whose TypeDefinition is one ObjectType and which one folder organizes: two nodes with
    /// `n` inverse references each.
    ManyReferences,
    /// `n` objects, each naming its parent folder through an alias of its own (`n` aliases).
    ManyAliases,
    /// Blocks of ten nodes the way companion specs look: an ObjectType with four members (properties and
    /// variables with values, descriptions), and an instance of it with its four variables.
    Mixed,
}

impl Shape {
    pub const ALL: [Shape; 6] =
        [Shape::Siblings, Shape::DeepInstances, Shape::DeepTypes, Shape::ManyReferences, Shape::ManyAliases, Shape::Mixed];

    pub fn name(self) -> &'static str {
        match self {
            Shape::Siblings => "siblings",
            Shape::DeepInstances => "deep-instances",
            Shape::DeepTypes => "deep-types",
            Shape::ManyReferences => "many-references",
            Shape::ManyAliases => "many-aliases",
            Shape::Mixed => "mixed",
        }
    }
}

fn header(out: &mut String, aliases: usize) {
    out.push_str("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n");
    out.push_str("<UANodeSet xmlns=\"http://opcfoundation.org/UA/2011/03/UANodeSet.xsd\">\n");
    let _ = writeln!(out, "  <NamespaceUris>\n    <Uri>{URI}</Uri>\n  </NamespaceUris>");
    let _ = writeln!(
        out,
        "  <Models>\n    <Model ModelUri=\"{URI}\" Version=\"1.0.0\" PublicationDate=\"2026-01-01T00:00:00Z\">\n      \
         <RequiredModel ModelUri=\"http://opcfoundation.org/UA/\" Version=\"1.05.00\"/>\n    </Model>\n  </Models>"
    );
    out.push_str("  <Aliases>\n");
    for (alias, id) in [
        ("Int32", "i=6"),
        ("Double", "i=11"),
        ("String", "i=12"),
        ("Organizes", "i=35"),
        ("HasModellingRule", "i=37"),
        ("HasTypeDefinition", "i=40"),
        ("HasSubtype", "i=45"),
        ("HasProperty", "i=46"),
        ("HasComponent", "i=47"),
    ] {
        let _ = writeln!(out, "    <Alias Alias=\"{alias}\">{id}</Alias>");
    }
    for k in 0..aliases {
        let _ = writeln!(out, "    <Alias Alias=\"Folder{k}\">ns=1;i=1</Alias>");
    }
    out.push_str("  </Aliases>\n");
}

fn object(out: &mut String, id: usize, name: &str, type_def: &str, parent: (&str, &str)) {
    let _ = write!(
        out,
        "  <UAObject NodeId=\"ns=1;i={id}\" BrowseName=\"1:{name}\">\n    <DisplayName>{name}</DisplayName>\n    <References>\n      \
         <Reference ReferenceType=\"HasTypeDefinition\">{type_def}</Reference>\n      \
         <Reference ReferenceType=\"{}\" IsForward=\"false\">{}</Reference>\n    </References>\n  </UAObject>\n",
        parent.0, parent.1
    );
}

/// A model of `n` nodes (about; a few more for the parents some shapes need) in the given shape.
pub fn nodeset(shape: Shape, n: usize) -> String {
    let mut out = String::with_capacity(n * 400 + 2000);
    header(&mut out, if shape == Shape::ManyAliases { n } else { 0 });
    match shape {
        Shape::Siblings => {
            object(&mut out, 1, "Parent", "i=58", ("Organizes", "i=85"));
            for k in 0..n {
                let _ = write!(
                    out,
                    "  <UAVariable NodeId=\"ns=1;i={}\" BrowseName=\"1:V{k}\" ParentNodeId=\"ns=1;i=1\" DataType=\"Int32\">\n    \
                     <DisplayName>V{k}</DisplayName>\n    <References>\n      \
                     <Reference ReferenceType=\"HasTypeDefinition\">i=63</Reference>\n      \
                     <Reference ReferenceType=\"HasComponent\" IsForward=\"false\">ns=1;i=1</Reference>\n    </References>\n    \
                     <Value>\n      <Int32 xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\">{k}</Int32>\n    </Value>\n  </UAVariable>\n",
                    k + 2
                );
            }
        }
        Shape::DeepInstances => {
            for k in 0..n {
                let parent = if k == 0 { ("Organizes", "i=85".to_string()) } else { ("HasComponent", format!("ns=1;i={k}")) };
                object(&mut out, k + 1, &format!("Level{k}"), "i=58", (parent.0, &parent.1));
            }
        }
        Shape::DeepTypes => {
            for k in 0..n {
                let base = if k == 0 { "i=58".to_string() } else { format!("ns=1;i={k}") };
                let _ = write!(
                    out,
                    "  <UAObjectType NodeId=\"ns=1;i={}\" BrowseName=\"1:Type{k}\">\n    <DisplayName>Type{k}</DisplayName>\n    \
                     <References>\n      <Reference ReferenceType=\"HasSubtype\" IsForward=\"false\">{base}</Reference>\n    \
                     </References>\n  </UAObjectType>\n",
                    k + 1
                );
            }
        }
        Shape::ManyReferences => {
            let _ = write!(
                out,
                "  <UAObjectType NodeId=\"ns=1;i=1\" BrowseName=\"1:TargetType\">\n    <DisplayName>TargetType</DisplayName>\n    \
                 <References>\n      <Reference ReferenceType=\"HasSubtype\" IsForward=\"false\">i=58</Reference>\n    \
                 </References>\n  </UAObjectType>\n"
            );
            object(&mut out, 2, "Folder", "i=61", ("Organizes", "i=85"));
            for k in 0..n {
                object(&mut out, k + 3, &format!("O{k}"), "ns=1;i=1", ("Organizes", "ns=1;i=2"));
            }
        }
        Shape::ManyAliases => {
            object(&mut out, 1, "Folder", "i=61", ("Organizes", "i=85"));
            for k in 0..n {
                object(&mut out, k + 2, &format!("O{k}"), "i=58", ("Organizes", &format!("Folder{k}")));
            }
        }
        Shape::Mixed => {
            for b in 0..n.div_ceil(10) {
                mixed_block(&mut out, b);
            }
        }
    }
    out.push_str("</UANodeSet>\n");
    out
}

/// One block of [`Shape::Mixed`]: ten nodes, NodeIds `ns=1;i=10b+1` to `10b+10`.
fn mixed_block(out: &mut String, b: usize) {
    let id = |k: usize| 10 * b + k;
    let _ = write!(
        out,
        "  <UAObjectType NodeId=\"ns=1;i={}\" BrowseName=\"1:DeviceType{b}\">\n    <DisplayName>DeviceType{b}</DisplayName>\n    \
         <Description>A synthetic device type, number {b}, with two properties and two variables.</Description>\n    \
         <References>\n      <Reference ReferenceType=\"HasSubtype\" IsForward=\"false\">i=58</Reference>\n    </References>\n  \
         </UAObjectType>\n",
        id(1)
    );
    object(out, id(2), &format!("Device{b}"), &format!("ns=1;i={}", id(1)), ("Organizes", "i=85"));
    // Four members of the type (3-6) and the instance's four variables (7-10).
    for (owner, first, rule) in [(id(1), 3, true), (id(2), 7, false)] {
        for m in 0..4 {
            let (name, dt, type_def, reference, value) = match m {
                0 => ("SerialNumber", "String", "i=68", "HasProperty", format!("<String xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\">SN-{b:08}-{owner}</String>")),
                1 => ("Revision", "Int32", "i=68", "HasProperty", format!("<Int32 xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\">{b}</Int32>")),
                2 => ("Temperature", "Double", "i=63", "HasComponent", format!("<Double xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\">{}.5</Double>", b % 100)),
                _ => ("Status", "String", "i=63", "HasComponent", "<String xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\">running</String>".to_string()),
            };
            let rule = if rule { "\n      <Reference ReferenceType=\"HasModellingRule\">i=78</Reference>" } else { "" };
            let _ = write!(
                out,
                "  <UAVariable NodeId=\"ns=1;i={}\" BrowseName=\"1:{name}\" ParentNodeId=\"ns=1;i={owner}\" DataType=\"{dt}\">\n    \
                 <DisplayName>{name}</DisplayName>\n    <Description>The {name} of synthetic device {b}.</Description>\n    \
                 <References>\n      <Reference ReferenceType=\"HasTypeDefinition\">{type_def}</Reference>{rule}\n      \
                 <Reference ReferenceType=\"{reference}\" IsForward=\"false\">ns=1;i={owner}</Reference>\n    </References>\n    \
                 <Value>\n      {value}\n    </Value>\n  </UAVariable>\n",
                id(first + m)
            );
        }
    }
}

/// A [`Shape::Mixed`] model of at least `bytes` bytes.
pub fn of_size(bytes: usize) -> String {
    let mut out = String::with_capacity(bytes + 4096);
    header(&mut out, 0);
    let mut b = 0;
    while out.len() < bytes {
        mixed_block(&mut out, b);
        b += 1;
    }
    out.push_str("</UANodeSet>\n");
    out
}
