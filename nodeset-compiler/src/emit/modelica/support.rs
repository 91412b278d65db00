//! The `OpcUaSupport` package: connectors and configuration records every generated package uses.
//!
//! Its sources are hand-written Modelica kept beside this module (`support/*.mo`) and compiled into the
//! binary, so the generator needs no files at run time. Only the header and the version are added here.
//! `Resources/Include` holds the C header of the `nodeset_live` library that `OpcUaSupport.Live` calls;
//! the library itself is built from the `nodeset-live` crate and placed in `Resources/Library/<platform>`.

use super::text;
use crate::write::OutFile;
use std::path::PathBuf;

/// The name of the support package; generated code refers to it by this name.
pub const PACKAGE: &str = "OpcUaSupport";

/// The version written into its `version` annotation and into the `uses` annotations that refer to it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

const SOURCES: &[(&str, &str)] = &[
    ("package.mo", include_str!("support/package.mo")),
    ("package.order", include_str!("support/package.order")),
    ("RealInput.mo", include_str!("support/RealInput.mo")),
    ("RealOutput.mo", include_str!("support/RealOutput.mo")),
    ("IntegerInput.mo", include_str!("support/IntegerInput.mo")),
    ("IntegerOutput.mo", include_str!("support/IntegerOutput.mo")),
    ("BooleanInput.mo", include_str!("support/BooleanInput.mo")),
    ("BooleanOutput.mo", include_str!("support/BooleanOutput.mo")),
    ("StringInput.mo", include_str!("support/StringInput.mo")),
    ("StringOutput.mo", include_str!("support/StringOutput.mo")),
    ("NodeIdType.mo", include_str!("support/NodeIdType.mo")),
    ("BuiltinType.mo", include_str!("support/BuiltinType.mo")),
    ("NodeId.mo", include_str!("support/NodeId.mo")),
    ("BrowsePath.mo", include_str!("support/BrowsePath.mo")),
    ("VariableNode.mo", include_str!("support/VariableNode.mo")),
    ("Nodes.mo", include_str!("support/Nodes.mo")),
    ("Interfaces/package.mo", include_str!("support/Interfaces/package.mo")),
    ("Interfaces/package.order", include_str!("support/Interfaces/package.order")),
    ("Interfaces/Connection.mo", include_str!("support/Interfaces/Connection.mo")),
    ("Interfaces/ReadReal.mo", include_str!("support/Interfaces/ReadReal.mo")),
    ("Interfaces/WriteReal.mo", include_str!("support/Interfaces/WriteReal.mo")),
    ("Interfaces/ReadInteger.mo", include_str!("support/Interfaces/ReadInteger.mo")),
    ("Interfaces/WriteInteger.mo", include_str!("support/Interfaces/WriteInteger.mo")),
    ("Interfaces/ReadBoolean.mo", include_str!("support/Interfaces/ReadBoolean.mo")),
    ("Interfaces/WriteBoolean.mo", include_str!("support/Interfaces/WriteBoolean.mo")),
    ("Interfaces/ReadString.mo", include_str!("support/Interfaces/ReadString.mo")),
    ("Interfaces/WriteString.mo", include_str!("support/Interfaces/WriteString.mo")),
    ("Loopback/package.mo", include_str!("support/Loopback/package.mo")),
    ("Loopback/package.order", include_str!("support/Loopback/package.order")),
    ("Loopback/ReadReal.mo", include_str!("support/Loopback/ReadReal.mo")),
    ("Loopback/WriteReal.mo", include_str!("support/Loopback/WriteReal.mo")),
    ("Loopback/ReadInteger.mo", include_str!("support/Loopback/ReadInteger.mo")),
    ("Loopback/WriteInteger.mo", include_str!("support/Loopback/WriteInteger.mo")),
    ("Loopback/ReadBoolean.mo", include_str!("support/Loopback/ReadBoolean.mo")),
    ("Loopback/WriteBoolean.mo", include_str!("support/Loopback/WriteBoolean.mo")),
    ("Loopback/ReadString.mo", include_str!("support/Loopback/ReadString.mo")),
    ("Loopback/WriteString.mo", include_str!("support/Loopback/WriteString.mo")),
    ("Live/package.mo", include_str!("support/Live/package.mo")),
    ("Live/package.order", include_str!("support/Live/package.order")),
    ("Live/Server/package.mo", include_str!("support/Live/Server/package.mo")),
    ("Live/Server/package.order", include_str!("support/Live/Server/package.order")),
    ("Live/Server/Endpoint.mo", include_str!("support/Live/Server/Endpoint.mo")),
    ("Live/Server/ReadReal.mo", include_str!("support/Live/Server/ReadReal.mo")),
    ("Live/Server/WriteReal.mo", include_str!("support/Live/Server/WriteReal.mo")),
    ("Live/Server/ReadInteger.mo", include_str!("support/Live/Server/ReadInteger.mo")),
    ("Live/Server/WriteInteger.mo", include_str!("support/Live/Server/WriteInteger.mo")),
    ("Live/Server/ReadBoolean.mo", include_str!("support/Live/Server/ReadBoolean.mo")),
    ("Live/Server/WriteBoolean.mo", include_str!("support/Live/Server/WriteBoolean.mo")),
    ("Live/Server/ReadString.mo", include_str!("support/Live/Server/ReadString.mo")),
    ("Live/Server/WriteString.mo", include_str!("support/Live/Server/WriteString.mo")),
    ("Live/Client/package.mo", include_str!("support/Live/Client/package.mo")),
    ("Live/Client/package.order", include_str!("support/Live/Client/package.order")),
    ("Live/Client/Endpoint.mo", include_str!("support/Live/Client/Endpoint.mo")),
    ("Live/Client/ReadReal.mo", include_str!("support/Live/Client/ReadReal.mo")),
    ("Live/Client/WriteReal.mo", include_str!("support/Live/Client/WriteReal.mo")),
    ("Live/Client/ReadInteger.mo", include_str!("support/Live/Client/ReadInteger.mo")),
    ("Live/Client/WriteInteger.mo", include_str!("support/Live/Client/WriteInteger.mo")),
    ("Live/Client/ReadBoolean.mo", include_str!("support/Live/Client/ReadBoolean.mo")),
    ("Live/Client/WriteBoolean.mo", include_str!("support/Live/Client/WriteBoolean.mo")),
    ("Live/Client/ReadString.mo", include_str!("support/Live/Client/ReadString.mo")),
    ("Live/Client/WriteString.mo", include_str!("support/Live/Client/WriteString.mo")),
    // The C header of the nodeset_live library the `Include` annotations of `Live` name: its one home
    // (nodeset-live's tests check it against the library's exports and compile their C programs with it).
    ("Resources/Include/nodeset_live.h", include_str!("support/Resources/Include/nodeset_live.h")),
];

/// The support package as files below the output root.
pub fn files() -> Vec<OutFile> {
    SOURCES
        .iter()
        .map(|(name, body)| {
            let body = body
                .replace("{VERSION}", VERSION)
                .replace("{RECORD_ICON}", text::RECORD_ICON)
                .replace("{BLOCK_ICON}", text::BLOCK_ICON)
                .replace("{PACKAGE_ICON}", text::PACKAGE_ICON)
                .replace("{INFO_ICON}", text::INFO_ICON);
            // package.order is a list of class names and may hold nothing else (MLS 13.4.3), so no header.
            let contents = if name.ends_with(".order") { body } else { format!("{}{body}", text::header(None)) };
            OutFile { path: PathBuf::from(PACKAGE).join(name), contents }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    #[test]
    fn every_class_is_listed_in_the_package_order_and_has_a_file_or_is_nested_in_the_package() {
        let files = files();
        // Resources/ holds files for the Modelica tool (the C header), not classes.
        let resources = PathBuf::from(PACKAGE).join("Resources");
        let folders: BTreeSet<PathBuf> =
            files.iter().map(|f| f.path.parent().unwrap().to_path_buf()).filter(|d| !d.starts_with(&resources)).collect();
        assert!(folders.len() >= 3, "{folders:?}");
        for folder in &folders {
            let in_folder = |name: &str| files.iter().find(|f| f.path == folder.join(name));
            let order = &in_folder("package.order").unwrap_or_else(|| panic!("{}: no package.order", folder.display())).contents;
            let mut listed: Vec<&str> = order.lines().collect();
            // Class files, sub-packages (folders) and classes nested in package.mo (the UsersGuide, which holds
            // documentation only and so is checked whenever a tool loads the package, not as a class of its own).
            let mut classes: Vec<String> = files
                .iter()
                .filter(|f| f.path.parent() == Some(folder.as_path()))
                .filter_map(|f| f.path.file_name()?.to_str()?.strip_suffix(".mo").map(str::to_string))
                .filter(|n| n != "package")
                .collect();
            classes.extend(folders.iter().filter(|d| d.parent() == Some(folder.as_path())).map(|d| d.file_name().unwrap().to_str().unwrap().to_string()));
            let package = &in_folder("package.mo").unwrap_or_else(|| panic!("{}: no package.mo", folder.display())).contents;
            classes.extend(package.lines().filter_map(|l| l.strip_prefix("  package ")?.split_whitespace().next().map(str::to_string)));
            classes.sort();
            listed.sort();
            assert_eq!(listed, classes, "{}", folder.display());
            let within_folder = folder.to_str().unwrap().replace('/', ".");
            for f in files.iter().filter(|f| f.path.parent() == Some(folder.as_path())) {
                if let Some(class) = f.path.file_name().unwrap().to_str().unwrap().strip_suffix(".mo") {
                    let within = match (class, folder.parent()) {
                        ("package", Some(p)) if p.as_os_str().is_empty() => "within;".to_string(),
                        ("package", _) => format!("within {};", folder.parent().unwrap().to_str().unwrap().replace('/', ".")),
                        _ => format!("within {within_folder};"),
                    };
                    assert!(f.contents.contains(&within), "{}: {within}", f.path.display());
                    assert!(f.contents.starts_with("// Generated by nodeset-compiler"), "{}", f.path.display());
                    assert!(!f.contents.contains("_ICON}"), "{}: an icon placeholder is left", f.path.display());
                }
            }
        }
    }
}
