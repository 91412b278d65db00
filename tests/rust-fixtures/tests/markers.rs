//! Member markers as the emitter writes them decode, with the runtime's `MemberPath`, into the BrowseNames
//! of the nodeset: names holding `/`, `\`, `-`, `+` and keywords included.

use nodeset_fixture_code::names;
use nodeset_models::runtime::typed::MemberPath;

fn segments(path: MemberPath) -> Vec<(&'static str, String)> {
    path.segments().unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn awkward_browse_names_survive_the_marker_path() {
    use names::objects::members::ThreeDFrameType as Frame;
    let uri = names::NAMESPACE_URI;
    assert_eq!(Frame::In_Out_Level.path, r"0:In\/Out\\Level");
    assert_eq!(segments(Frame::In_Out_Level.browse_path()), [(uri, r"In/Out\Level".to_string())]);
    assert_eq!(segments(Frame::Mode_A.browse_path()), [(uri, "Mode-A".to_string())]);
    assert_eq!(segments(Frame::Precise_.browse_path()), [(uri, "Precise+".to_string())]);
    assert_eq!(segments(Frame::Self_.browse_path()), [(uri, "Self".to_string())]);
    assert_eq!(segments(Frame::Type.browse_path()), [(uri, "Type".to_string())]);
    assert!(!Frame::In_Out_Level.mandatory && Frame::Type.mandatory);
}
