//! Browse paths whose segments leave out their namespace, against a running server where one name is
//! reachable in two namespaces at one place.
//!
//! No example server has such a place (the robot, the robot cell and the node-opcua peer name every
//! sibling differently), so this test serves ns0, DI, IA and Robotics on loopback and adds one: a folder
//! `Station` holding two Robotics `AxisType` instances both named `Axis`, one in the server's own namespace
//! and one in the Robotics namespace, and only the second with the Optional `ParameterSet/ActualSpeed`.
//! `RemoteServer::find` and `bind_path` then:
//!
//! - call `Station/Axis` ambiguous, listing both nodes with every segment qualified, and refuse to bind it;
//! - bind each of those qualified paths to its own node;
//! - follow both axes on when the path goes further, so that `Station/Axis/ParameterSet/ActualSpeed`, which
//!   only one of them has, is found, while `Station/Axis/ParameterSet/ActualPosition` is ambiguous again.

mod common;

use common::serve;
use nodeset_models::models::robotics::objects::AxisType;
use nodeset_models::models::{di, ia, robotics};
use nodeset_models::runtime::client::ClientError;
use nodeset_models::runtime::remote::{RemoteError, RemoteServer};
use nodeset_models::runtime::server::ServerConfig;
use nodeset_models::runtime::typed::{Instantiate, ObjectType};
use opcua::types::{NodeId, ObjectId, ObjectTypeId, QualifiedName};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_name_in_two_namespaces_at_one_place_is_ambiguous_until_qualified() {
    let config = ServerConfig::new("client paths test")
        .table(&di::TABLE)
        .type_loader(di::TypeLoader)
        .table(&ia::TABLE)
        .type_loader(ia::TypeLoader)
        .table(&robotics::TABLE)
        .type_loader(robotics::TypeLoader);
    let running = serve(config).await;
    let m = &running.manager;
    let own = m.instance_namespace();
    let robotics_ns = m.namespace_index(AxisType::TYPE_ID.namespace_uri).expect("the server serves Robotics");
    assert_ne!(own, robotics_ns);
    let axis_type = m.resolve(AxisType::TYPE_ID).expect("AxisType on the server");
    let station = m
        .instantiate(
            &ObjectTypeId::FolderType.into(),
            &ObjectId::ObjectsFolder.into(),
            QualifiedName::new(own, "Station"),
            &Instantiate::new(),
        )
        .expect("the folder");
    let own_axis = m
        .instantiate(&axis_type, &station, QualifiedName::new(own, "Axis"), &Instantiate::new().node_id(NodeId::new(own, "OwnAxis")))
        .expect("the axis in the server's namespace");
    let robotics_axis = m
        .instantiate(
            &axis_type,
            &station,
            QualifiedName::new(robotics_ns, "Axis"),
            &Instantiate::new().node_id(NodeId::new(own, "RoboticsAxis")).optional("ParameterSet/ActualSpeed"),
        )
        .expect("the axis in the Robotics namespace");

    let client = RemoteServer::connect(&running.url).await.expect("a session over None on loopback");
    let uri = |ns: u16| -> String {
        let context = client.session().encoding_context().read();
        let known = context.namespaces().known_namespaces();
        known.iter().find(|(_, i)| **i == ns).map(|(u, _)| u.clone()).unwrap_or_else(|| panic!("namespace {ns} on the client"))
    };
    let (own_uri, robotics_uri) = (uri(own), uri(robotics_ns));
    assert_eq!(robotics_uri, AxisType::TYPE_ID.namespace_uri);
    let own_path = format!("{{{own_uri}}}Station/{{{own_uri}}}Axis");
    let robotics_path = format!("{{{own_uri}}}Station/{{{robotics_uri}}}Axis");
    // The qualified paths in the order the error lists them (by their text).
    let mut both = vec![own_path.clone(), robotics_path.clone()];
    both.sort();

    // Unqualified, the path ends at two nodes: an error that names both, never one of them picked.
    match client.find("Station/Axis").await {
        Err(RemoteError::Ambiguous { path, matches }) => {
            assert_eq!(path, "Station/Axis");
            assert_eq!(matches, both);
        }
        other => panic!("`Station/Axis` leads to two axes, found {other:?}"),
    }
    let error = client.find("Station/Axis").await.unwrap_err().to_string();
    assert!(error.starts_with("`Station/Axis` leads to 2 nodes; name the one meant by namespace URIs: "), "{error}");
    assert!(error.contains(&own_path) && error.contains(&robotics_path), "{error}");
    // bind_path refuses it the same way, before looking at the type (both axes are AxisTypes).
    match client.bind_path::<AxisType>("Station/Axis").await {
        Err(ClientError::Remote(RemoteError::Ambiguous { matches, .. })) => assert_eq!(matches, both),
        other => panic!("bind_path of an ambiguous path: {:?}", other.map(|r| r.node().clone())),
    }

    // Each qualified path the error suggests binds its own node, in one request.
    let found = client.find_counted(&own_path).await.expect("the own axis by its qualified path");
    assert_eq!((&found.node, found.requests), (&own_axis, 1), "{found:?}");
    let bound = client.bind_path::<AxisType>(&robotics_path).await.expect("the Robotics axis by its qualified path");
    assert_eq!(bound.node(), &robotics_axis);
    // Qualifying only the segment that differs is enough.
    let bound = client.bind_path::<AxisType>(&format!("Station/{{{robotics_uri}}}Axis")).await.expect("one segment qualified");
    assert_eq!(bound.node(), &robotics_axis);

    // Both axes are followed on: a member only the Robotics axis has makes the path unique again ...
    let speed = client.find_counted("Station/Axis/ParameterSet/ActualSpeed").await.expect("ActualSpeed of the one axis that has it");
    assert!(speed.path.starts_with(&format!("{robotics_path}/")), "{speed:?}");
    // ... and one both have leaves it ambiguous, with the two full paths.
    match client.find("Station/Axis/ParameterSet/ActualPosition").await {
        Err(RemoteError::Ambiguous { path, matches }) => {
            assert_eq!(path, "Station/Axis/ParameterSet/ActualPosition");
            assert_eq!(matches.len(), 2, "{matches:?}");
            assert!(matches[0].starts_with(&format!("{}/", both[0])) && matches[1].starts_with(&format!("{}/", both[1])), "{matches:?}");
        }
        other => panic!("ActualPosition of two axes, found {other:?}"),
    }

    client.disconnect().await;
    running.stop().await;
}
