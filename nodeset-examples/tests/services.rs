//! The model node manager through OPC UA services, with async-opcua's client over loopback: browse and
//! read, writes with their status codes, method calls with argument validation, and values set by user
//! code reaching subscriptions.

mod common;

use std::sync::{Arc, Mutex};
use std::time::Duration;

use common::{connect, disconnect, read, serve};
use nodeset_examples::demo::{self, ids, DemoMode, DemoPoint};
use nodeset_models::runtime::server::{MethodError, MethodInvocation, ServerConfig};
use opcua::client::DataChangeCallback;
use opcua::types::{
    Argument, AttributeId, BrowseDescription, BrowseDirection, BrowseResultMask, CallMethodResult, DataValue,
    ExtensionObject, LocalizedText, MonitoredItemCreateRequest, NodeClass, NodeId, QualifiedName, StatusCode,
    StructureDefinition, TimestampsToReturn, TryFromVariant, Variant, VariantScalarTypeId, WriteValue,
};

fn demo_config() -> ServerConfig {
    ServerConfig::new("services test").table(&demo::TABLE).type_loader(demo::TypeLoader)
}

fn write_value(node: &NodeId, attribute: AttributeId, value: impl Into<Variant>) -> WriteValue {
    WriteValue {
        node_id: node.clone(),
        attribute_id: attribute as u32,
        value: DataValue::value_only(value.into()),
        ..Default::default()
    }
}

#[tokio::test]
async fn browse_and_read_over_the_wire() {
    let running = serve(demo_config()).await;
    let ns = running.manager.namespace_index(demo::NAMESPACE_URI).unwrap();
    let id = |n: u32| NodeId::new(ns, n);
    let (session, event_loop) = connect(&running.url).await;
    session.add_type_loader(Arc::new(demo::TypeLoader));
    assert_eq!(session.get_namespace_index(demo::NAMESPACE_URI).await.unwrap(), ns);

    // ObjectsFolder organizes both pumps, with their type definitions.
    let browse = BrowseDescription {
        node_id: NodeId::new(0, 85u32),
        browse_direction: BrowseDirection::Forward,
        reference_type_id: NodeId::new(0, 35u32),
        include_subtypes: true,
        node_class_mask: 0,
        result_mask: BrowseResultMask::All as u32,
    };
    let result = session.browse(&[browse], 0, None).await.unwrap().remove(0);
    let refs = result.references.unwrap_or_default();
    let pump1 = refs.iter().find(|r| r.node_id.node_id == id(ids::PUMP1)).expect("Pump1 under Objects");
    assert_eq!(pump1.browse_name, QualifiedName::new(ns, "Pump1"));
    assert_eq!(pump1.node_class, NodeClass::Object);
    assert_eq!(pump1.type_definition.node_id, id(ids::PUMP_TYPE));
    assert!(refs.iter().any(|r| r.node_id.node_id == id(ids::PUMP2)));

    match read(&session, &id(ids::PUMP1), AttributeId::Description).await.1 {
        Variant::LocalizedText(t) => assert_eq!(t.text.as_ref(), "The first pump."),
        other => panic!("Description is {other:?}"),
    }
    assert_eq!(read(&session, &id(ids::PUMP1_SPEED), AttributeId::Value).await.1, Variant::Double(12.5));
    // A structure value decodes with the type loader once the session knows the namespace table.
    let position = read(&session, &id(ids::PUMP1_POSITION), AttributeId::Value).await.1;
    assert_eq!(
        DemoPoint::try_from_variant(position).unwrap(),
        DemoPoint { x: 3.0, y: 4.0, label: "home".into(), mode: DemoMode::Fast }
    );
    match read(&session, &id(ids::DEMO_POINT), AttributeId::DataTypeDefinition).await.1 {
        Variant::ExtensionObject(eo) => {
            let def = eo.inner_as::<StructureDefinition>().expect("a StructureDefinition");
            assert_eq!(def.default_encoding_id, id(ids::DEMO_POINT_DEFAULT_BINARY));
        }
        other => panic!("DataTypeDefinition is {other:?}"),
    }
    match read(&session, &id(ids::PUMP1_EMPTY), AttributeId::Value).await.1 {
        Variant::Array(a) => assert_eq!((a.value_type, a.values.len()), (VariantScalarTypeId::Int32, 0)),
        other => panic!("an empty Int32 array, not {other:?}"),
    }
    disconnect(session, event_loop).await;
    running.stop().await;
}

#[tokio::test]
async fn writes_are_checked_then_handled() {
    let running = serve(demo_config()).await;
    let m = running.manager.clone();
    let ns = m.namespace_index(demo::NAMESPACE_URI).unwrap();
    let id = |n: u32| NodeId::new(ns, n);
    m.on_write(&id(ids::PUMP1_SPEED), |v| match v {
        Variant::Double(d) if *d > 100.0 => Err(StatusCode::BadOutOfRange),
        _ => Ok(None),
    });
    // A handler may store something else than what was written.
    m.on_write(&id(ids::PUMP1_NAME), |v| match v {
        Variant::LocalizedText(t) => Ok(Some(LocalizedText::new("en", &t.text.as_ref().to_uppercase()).into())),
        _ => Ok(None),
    });
    let (session, event_loop) = connect(&running.url).await;
    session.add_type_loader(Arc::new(demo::TypeLoader));
    let point = DemoPoint { x: 1.0, y: 2.0, label: "there".into(), mode: DemoMode::Slow };
    let argument = ExtensionObject::from_message(Argument::default());
    let cases: Vec<(&str, WriteValue, StatusCode)> = vec![
        ("Double to Double", write_value(&id(ids::PUMP1_SPEED), AttributeId::Value, 42.0), StatusCode::Good),
        (
            "the handler's range",
            write_value(&id(ids::PUMP1_SPEED), AttributeId::Value, 420.0),
            StatusCode::BadOutOfRange,
        ),
        (
            "String to Double",
            write_value(&id(ids::PUMP1_SPEED), AttributeId::Value, "fast"),
            StatusCode::BadTypeMismatch,
        ),
        (
            "Float to Double",
            write_value(&id(ids::PUMP1_SPEED), AttributeId::Value, 1.0f32),
            StatusCode::BadTypeMismatch,
        ),
        (
            "array to scalar",
            write_value(&id(ids::PUMP1_SPEED), AttributeId::Value, vec![1.0, 2.0]),
            StatusCode::BadTypeMismatch,
        ),
        (
            "null to Double",
            write_value(&id(ids::PUMP1_SPEED), AttributeId::Value, Variant::Empty),
            StatusCode::BadTypeMismatch,
        ),
        ("read-only", write_value(&id(ids::PUMP1_COUNTER), AttributeId::Value, 1i32), StatusCode::BadNotWritable),
        (
            "user read-only",
            write_value(&id(ids::PUMP1_OPERATOR_ONLY), AttributeId::Value, 1i32),
            StatusCode::BadUserAccessDenied,
        ),
        ("Int32 to an enumeration", write_value(&id(ids::PUMP1_MODE), AttributeId::Value, 10i32), StatusCode::Good),
        (
            "Int64 to an enumeration",
            write_value(&id(ids::PUMP1_MODE), AttributeId::Value, 10i64),
            StatusCode::BadTypeMismatch,
        ),
        (
            "Double to a subtype of Double",
            write_value(&id(ids::PUMP1_LIMIT), AttributeId::Value, 80.0),
            StatusCode::Good,
        ),
        (
            "UInt32 to a subtype of Double",
            write_value(&id(ids::PUMP1_LIMIT), AttributeId::Value, 80u32),
            StatusCode::BadTypeMismatch,
        ),
        (
            "String[] to String[]",
            write_value(&id(ids::PUMP1_TAGS), AttributeId::Value, vec!["a", "b", "c"]),
            StatusCode::Good,
        ),
        ("String to String[]", write_value(&id(ids::PUMP1_TAGS), AttributeId::Value, "a"), StatusCode::BadTypeMismatch),
        (
            "Int32[] to String[]",
            write_value(&id(ids::PUMP1_TAGS), AttributeId::Value, vec![1i32]),
            StatusCode::BadTypeMismatch,
        ),
        ("structure", write_value(&id(ids::PUMP1_POSITION), AttributeId::Value, point.clone()), StatusCode::Good),
        (
            "another structure",
            write_value(&id(ids::PUMP1_POSITION), AttributeId::Value, argument),
            StatusCode::BadTypeMismatch,
        ),
        (
            "Double to a structure",
            write_value(&id(ids::PUMP1_POSITION), AttributeId::Value, 1.0),
            StatusCode::BadTypeMismatch,
        ),
        (
            "LocalizedText",
            write_value(&id(ids::PUMP1_NAME), AttributeId::Value, LocalizedText::new("en", "x")),
            StatusCode::Good,
        ),
        (
            "DisplayName without WriteMask",
            write_value(&id(ids::PUMP1), AttributeId::DisplayName, LocalizedText::new("", "P")),
            StatusCode::BadNotWritable,
        ),
        ("Value of an object", write_value(&id(ids::PUMP1), AttributeId::Value, 1.0), StatusCode::BadNotWritable),
        ("unknown node", write_value(&id(99999), AttributeId::Value, 1.0), StatusCode::BadNodeIdUnknown),
    ];
    let writes: Vec<WriteValue> = cases.iter().map(|c| c.1.clone()).collect();
    let results = session.write(&writes).await.unwrap();
    for ((name, _, expected), got) in cases.iter().zip(&results) {
        assert_eq!(got, expected, "{name}");
    }
    assert_eq!(read(&session, &id(ids::PUMP1_SPEED), AttributeId::Value).await.1, Variant::Double(42.0));
    assert_eq!(read(&session, &id(ids::PUMP1_MODE), AttributeId::Value).await.1, Variant::Int32(10));
    assert_eq!(read(&session, &id(ids::PUMP1_LIMIT), AttributeId::Value).await.1, Variant::Double(80.0));
    assert_eq!(
        DemoPoint::try_from_variant(read(&session, &id(ids::PUMP1_POSITION), AttributeId::Value).await.1).unwrap(),
        point
    );
    assert_eq!(
        read(&session, &id(ids::PUMP1_NAME), AttributeId::Value).await.1,
        Variant::from(LocalizedText::new("en", "X"))
    );
    disconnect(session, event_loop).await;
    running.stop().await;
}

async fn call(
    session: &opcua::client::Session,
    object: &NodeId,
    method: &NodeId,
    args: Vec<Variant>,
) -> CallMethodResult {
    session.call_one((object.clone(), method.clone(), Some(args))).await.expect("the Call service answers")
}

#[tokio::test]
async fn method_calls_are_validated_then_dispatched() {
    let running = serve(demo_config()).await;
    let m = running.manager.clone();
    let ns = m.namespace_index(demo::NAMESPACE_URI).unwrap();
    let id = |n: u32| NodeId::new(ns, n);
    let (speed, mode) = (id(ids::PUMP1_SPEED), id(ids::PUMP1_MODE));
    m.on_call(&id(ids::PUMP1_START), move |call: MethodInvocation| {
        let (speed, mode) = (speed.clone(), mode.clone());
        async move {
            let s = f64::try_from_variant(call.arguments[0].clone()).map_err(|_| StatusCode::BadTypeMismatch)?;
            let raw = i32::try_from_variant(call.arguments[1].clone()).map_err(|_| StatusCode::BadTypeMismatch)?;
            if DemoMode::try_from(raw).is_err() {
                return Err(MethodError::Arguments(vec![StatusCode::Good, StatusCode::BadOutOfRange]));
            }
            call.manager.set_value(&speed, s)?;
            call.manager.set_value(&mode, raw)?;
            Ok(vec![Variant::Boolean(true)])
        }
    });
    let (session, event_loop) = connect(&running.url).await;
    session.add_type_loader(Arc::new(demo::TypeLoader));
    let (pump, start, mv) = (id(ids::PUMP1), id(ids::PUMP1_START), id(ids::PUMP1_MOVE));

    let ok = call(&session, &pump, &start, vec![30.0.into(), 10i32.into()]).await;
    assert_eq!(ok.status_code, StatusCode::Good);
    assert_eq!(ok.output_arguments, Some(vec![Variant::Boolean(true)]));
    assert_eq!(read(&session, &id(ids::PUMP1_SPEED), AttributeId::Value).await.1, Variant::Double(30.0));
    assert_eq!(read(&session, &id(ids::PUMP1_MODE), AttributeId::Value).await.1, Variant::Int32(10));

    let missing = call(&session, &pump, &start, vec![30.0.into()]).await;
    assert_eq!(missing.status_code, StatusCode::BadArgumentsMissing);
    let too_many = call(&session, &pump, &start, vec![1.0.into(), 5i32.into(), 3i32.into()]).await;
    assert_eq!(too_many.status_code, StatusCode::BadTooManyArguments);
    let wrong = call(&session, &pump, &start, vec!["fast".into(), 10i32.into()]).await;
    assert_eq!(wrong.status_code, StatusCode::BadInvalidArgument);
    assert_eq!(wrong.input_argument_results, Some(vec![StatusCode::BadTypeMismatch, StatusCode::Good]));
    let gap = call(&session, &pump, &start, vec![1.0.into(), 3i32.into()]).await;
    assert_eq!(gap.status_code, StatusCode::BadInvalidArgument);
    assert_eq!(gap.input_argument_results, Some(vec![StatusCode::Good, StatusCode::BadOutOfRange]));

    // async-opcua's in-memory node manager refuses a method whose Executable is false before ours sees
    // the call, and with BadUserAccessDenied rather than BadNotExecutable.
    let disabled = call(&session, &pump, &id(ids::PUMP1_DISABLED), vec![]).await;
    assert_eq!(disabled.status_code, StatusCode::BadUserAccessDenied);

    let target = DemoPoint { x: 6.0, y: 8.0, label: "far".into(), mode: DemoMode::Off };
    let unhandled = call(&session, &pump, &mv, vec![target.clone().into()]).await;
    assert_eq!(unhandled.status_code, StatusCode::BadNotImplemented);
    m.on_call(&mv, |call: MethodInvocation| async move {
        let p = DemoPoint::try_from_variant(call.arguments[0].clone()).map_err(|_| StatusCode::BadTypeMismatch)?;
        Ok(vec![Variant::Double((p.x * p.x + p.y * p.y).sqrt())])
    });
    let moved = call(&session, &pump, &mv, vec![target.into()]).await;
    assert_eq!(moved.status_code, StatusCode::Good);
    assert_eq!(moved.output_arguments, Some(vec![Variant::Double(10.0)]));
    let not_a_point = call(&session, &pump, &mv, vec![ExtensionObject::from_message(Argument::default()).into()]).await;
    assert_eq!(not_a_point.input_argument_results, Some(vec![StatusCode::BadTypeMismatch]));
    disconnect(session, event_loop).await;
    running.stop().await;
}

#[tokio::test]
async fn set_value_reaches_subscriptions() {
    let running = serve(demo_config()).await;
    let m = running.manager.clone();
    let counter = m.resolve(demo::node(ids::PUMP1_COUNTER)).expect("resolves");
    assert_eq!(m.set_value(&counter, "text"), Err(StatusCode::BadTypeMismatch));
    assert_eq!(m.set_value(&m.resolve(demo::node(ids::PUMP1)).unwrap(), 1i32), Err(StatusCode::BadAttributeIdInvalid));
    assert_eq!(m.set_value(&NodeId::new(0, 123456789u32), 1i32), Err(StatusCode::BadNodeIdUnknown));

    let (session, event_loop) = connect(&running.url).await;
    let seen = Arc::new(Mutex::new(Vec::new()));
    let sink = seen.clone();
    let subscription = session
        .create_subscription(
            Duration::from_millis(50),
            100,
            10,
            0,
            0,
            true,
            DataChangeCallback::new(move |dv, _| sink.lock().unwrap().push(dv.value.unwrap_or_default())),
        )
        .await
        .unwrap();
    let item = MonitoredItemCreateRequest::from(counter.clone());
    let created = session.create_monitored_items(subscription, TimestampsToReturn::Both, vec![item]).await.unwrap();
    assert_eq!(created[0].result.status_code, StatusCode::Good);
    tokio::time::sleep(Duration::from_millis(200)).await;
    m.set_value(&counter, 42i32).unwrap();
    let mut got = false;
    for _ in 0..100 {
        if seen.lock().unwrap().contains(&Variant::Int32(42)) {
            got = true;
            break;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert!(got, "the subscription saw {:?}", seen.lock().unwrap());
    assert_eq!(m.value(&counter).and_then(|dv| dv.value), Some(Variant::Int32(42)));
    disconnect(session, event_loop).await;
    running.stop().await;
}
