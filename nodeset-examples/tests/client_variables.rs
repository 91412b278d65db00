//! The typed client of VariableType instances (`runtime::client::Remote<H>` with a generated VariableType
//! handle) against the robot example (`examples/robot.rs`), started as a user starts it (its binary,
//! `--port 0`, secure by default) and reached over Basic256Sha256 SignAndEncrypt as an Operator.
//!
//! Each gear of the robot has a `Lifetime` variable of DI's LifetimeVariableType (an AnalogUnitType whose
//! DataType is the abstract `Number`, so its value is a `Variant`), counting down its remaining hours: it is
//! bound by browse path and by NodeId, its own value and its properties (EngineeringUnits, StartValue,
//! LimitValue; the Optional Indication absent) are read through the generated markers, its value is
//! subscribed, writes of the read-only value and property are refused with the server's status, and binds
//! with the wrong handle are refused: another VariableType, an ObjectType, and an object bound as a
//! VariableType. Each test starts its own robot.

#[path = "common/example.rs"]
mod example;

use std::path::PathBuf;
use std::time::Duration;

use example::{Process, PASSWORD};
use nodeset_models::models::di::objects::{members, LifetimeVariableType};
use nodeset_models::models::ia::objects::CalibrationValueType;
use nodeset_models::models::robotics::objects::GearType;
use nodeset_models::runtime::client::{ClientConfig, ClientError, Remote, Sample};
use nodeset_models::runtime::remote::RemoteServer;
use nodeset_models::runtime::typed::VariableType;
use opcua::types::{EUInformation, NodeId, StatusCode, Variant};

/// The first gear's lifetime, and its gear.
const GEAR: &str = "Robot/MotionDevices/Arm/PowerTrains/PT1/Gear";
const LIFETIME: &str = "Robot/MotionDevices/Arm/PowerTrains/PT1/Gear/Lifetime";

fn double(sample: &Sample<Variant>) -> f64 {
    match sample.value {
        Some(Variant::Double(v)) => v,
        ref other => panic!("a Double, not {other:?}"),
    }
}

/// The robot, started with a fresh PKI folder and user file, and an Operator's session to it.
struct Robot {
    _process: Process,
    client: RemoteServer,
    dir: PathBuf,
}

impl Drop for Robot {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

async fn robot(name: &str) -> Robot {
    let (dir, users) = example::operator_files("client-variables", name);
    let (server_pki, client_pki) = (dir.join("server-pki"), dir.join("client-pki"));
    let started = tokio::task::spawn_blocking(move || {
        let (pki, users) = (server_pki.to_str().expect("UTF-8").to_owned(), users.to_str().expect("UTF-8").to_owned());
        let robot = example::start("robot", &["--port", "0", "--pki", &pki, "--users", &users, "--trust-on-first-use"]);
        let url = robot.line("listening on ");
        (robot, url)
    });
    let (process, url) = started.await.unwrap();
    let client = ClientConfig::new(&client_pki).user("op", PASSWORD).trust_server_on_first_use().connect(&url).await.unwrap();
    Robot { _process: process, client, dir }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_gear_lifetime_is_bound_and_its_value_and_properties_read_typed() {
    let robot = robot("read").await;
    let client = &robot.client;

    // By browse path and by NodeId.
    let lifetime: Remote<LifetimeVariableType> = client.bind_path(LIFETIME).await.unwrap();
    let by_id: Remote<LifetimeVariableType> = client.bind(lifetime.node()).await.unwrap();
    assert_eq!(lifetime.node(), by_id.node());
    assert_eq!(format!("{lifetime:?}"), format!("Remote<LifetimeVariableType>({})", lifetime.node()));

    // Its own value, typed by the VariableType's DataType: `Number` is abstract, so a Variant (the robot
    // gives a Double, the hours left: 20000 less 1000 of earlier use for the first gear, less the run time).
    let value: Sample<Variant> = lifetime.read_value().await.unwrap();
    assert!(value.status.is_good() && value.source_timestamp.is_some(), "{value:?}");
    let left = double(&value);
    assert!((18_999.0..19_000.0).contains(&left), "the first gear's remaining hours: {left}");

    // Its properties, through the generated markers of `members::LifetimeVariableType`: EngineeringUnits
    // (inherited from AnalogUnitType, typed by its DataType EUInformation), StartValue and LimitValue
    // (Number: Variants), in one Read as a selection too; the Optional Indication is absent.
    let unit = lifetime.read::<EUInformation, _>(&members::LifetimeVariableType::EngineeringUnits).await.unwrap();
    let unit = unit.value.expect("EngineeringUnits has a value");
    assert_eq!((unit.display_name.text.as_ref(), unit.unit_id), ("h", 0x48_55_52), "hours, UNECE `HUR`: {unit:?}");
    let start = lifetime.read::<Variant, _>(&members::LifetimeVariableType::StartValue).await.unwrap();
    assert_eq!(start.value, Some(Variant::Double(20_000.0)));
    let selection = lifetime
        .read_selection(&[
            members::LifetimeVariableType::StartValue.browse_path(),
            members::LifetimeVariableType::LimitValue.browse_path(),
            members::LifetimeVariableType::Indication.browse_path(),
        ])
        .await
        .unwrap();
    let values: Vec<Option<Variant>> = selection.iter().map(|r| r.as_ref().ok().and_then(|d| d.value.clone())).collect();
    assert_eq!(values, [Some(Variant::Double(20_000.0)), Some(Variant::Double(0.0)), None], "{selection:?}");
    assert!(selection[2].is_err(), "the gear's lifetime has no Indication: {:?}", selection[2]);
    assert_eq!(lifetime.read_optional::<NodeId, _>(&members::LifetimeVariableType::Indication).await.unwrap(), None);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_gear_lifetime_is_subscribed_typed_and_counts_down() {
    let robot = robot("subscribe").await;
    let lifetime: Remote<LifetimeVariableType> = robot.client.bind_path(LIFETIME).await.unwrap();
    let left = double(&lifetime.read_value().await.unwrap());
    let mut samples = lifetime.subscribe_value(20).await.unwrap();
    let mut seen = Vec::new();
    while seen.len() < 4 {
        let s = tokio::time::timeout(Duration::from_secs(5), samples.next()).await.expect("a sample in time").expect("a sample");
        assert!(s.status.is_good() && s.source_timestamp.is_some(), "{s:?}");
        seen.push(double(&s));
    }
    assert!(seen.windows(2).all(|w| w[1] < w[0]), "the remaining hours count down: {seen:?}");
    assert!(seen[0] <= left, "the subscription starts after the read: {left} then {seen:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_typed_write_of_a_read_only_lifetime_is_refused_with_the_servers_status() {
    let robot = robot("write").await;
    let lifetime: Remote<LifetimeVariableType> = robot.client.bind_path(LIFETIME).await.unwrap();
    match lifetime.write_value(Variant::Double(1.0)).await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadNotWritable),
        other => panic!("a read-only lifetime was written: {other:?}"),
    }
    match lifetime.write(&members::LifetimeVariableType::LimitValue, Variant::Double(5.0)).await {
        Err(ClientError::Status { status, .. }) => assert_eq!(status, StatusCode::BadNotWritable),
        other => panic!("a read-only LimitValue was written: {other:?}"),
    }
    assert!((18_999.0..19_000.0).contains(&double(&lifetime.read_value().await.unwrap())), "the value is the robot's");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn binds_with_the_wrong_handle_are_refused() {
    let robot = robot("wrong").await;
    let client = &robot.client;
    // Another VariableType (IA's CalibrationValueType, an AnalogUnitType too, but no supertype of
    // LifetimeVariableType), with the TypeDefinition the variable has.
    let lifetime: Remote<LifetimeVariableType> = client.bind_path(LIFETIME).await.unwrap();
    match client.bind_path::<CalibrationValueType>(LIFETIME).await {
        Err(ClientError::WrongType { node, type_definition, expected }) => {
            assert_eq!((&node, expected), (lifetime.node(), CalibrationValueType::BROWSE_NAME));
            let di = LifetimeVariableType::TYPE_ID.namespace_uri;
            let index = client.session().get_namespace_index_from_cache(di).expect("the server has DI");
            assert_eq!(type_definition, Some(NodeId::new(index, 468)), "DI's LifetimeVariableType");
        }
        other => panic!("a LifetimeVariableType bound as a CalibrationValueType: {other:?}"),
    }
    match client.bind(lifetime.node()).await.map(|r: Remote<CalibrationValueType>| r.node().clone()) {
        Err(ClientError::WrongType { expected, .. }) => assert_eq!(expected, "CalibrationValueType"),
        other => panic!("a LifetimeVariableType bound by NodeId as a CalibrationValueType: {other:?}"),
    }
    // An ObjectType handle for the variable, and the VariableType handle for the gear (an object).
    match client.bind_path::<GearType>(LIFETIME).await {
        Err(ClientError::WrongType { expected, .. }) => assert_eq!(expected, "GearType"),
        other => panic!("a variable bound as a GearType: {other:?}"),
    }
    match client.bind_path::<LifetimeVariableType>(GEAR).await {
        Err(ClientError::WrongType { expected, .. }) => assert_eq!(expected, LifetimeVariableType::BROWSE_NAME),
        other => panic!("a gear bound as a LifetimeVariableType: {other:?}"),
    }
}
