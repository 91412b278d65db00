//! Generates the vendor's Robotics model and every model it requires into OUT_DIR: DI, IA and the OPC
//! Foundation's Robotics come from nodeset-models (mapped), the vendor's Device model is generated beside it.

fn main() {
    nodeset_compiler::build::Builder::new()
        .file("nodesets/Example.VendorRobotics.NodeSet2.xml")
        // The vendor's own models (the Device model) and the OPC Foundation's (DI, IA, Robotics).
        .models_dir("nodesets")
        .models_dir("../../nodesets/vendor")
        .extern_namespace("http://opcfoundation.org/UA/DI/", "nodeset_models::models::di")
        .extern_namespace("http://opcfoundation.org/UA/IA/", "nodeset_models::models::ia")
        .extern_namespace("http://opcfoundation.org/UA/Robotics/", "nodeset_models::models::robotics")
        .generate()
        .unwrap_or_else(|e| panic!("{e}"));
}
