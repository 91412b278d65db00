//! Load on a generated server: many client sessions (async-opcua's client) subscribed to every variable of
//! every axis of the `robot` example, while it updates its joints at 100 Hz and one more session writes a
//! writable variable. Loopback only, bounded in time; it stops by itself.
//!
//! ```text
//! cargo run --release -p nodeset-examples --example load -- --url opc.tcp://127.0.0.1:4856/ \
//!     [--sessions 50] [--seconds 300] [--publishing-ms 100] [--server-pid PID]
//! ```
//!
//! `cargo xtask load` starts the robot example and runs this against it. Each session creates one
//! subscription (publishing interval `--publishing-ms`) with one monitored item per variable under
//! `Robot/MotionDevices/Arm/Axes/<axis>` (found by browsing; sampling interval = publishing interval, queue
//! size 10, so a sample is lost only if a session's publishing stalls for ten intervals). The writer
//! session writes the controller's `ConfiguredDefaultStopMode` ten times a second and reads each value back.
//!
//! It prints a report and one `LOAD key=value ...` line, and exits non-zero when a session saw a gap in the
//! sequence numbers of its NotificationMessages, when any request, write, value or subscription status
//! was bad, or when fewer than 95% of the expected notifications arrived. Expected: per session, one
//! notification for the initial value and one per sampling interval since the session subscribed for each
//! joint position (the only axis variables that change: the robot sets them at 100 Hz, the server samples
//! them every interval), and one (the initial value) for each other axis variable.

use std::collections::HashSet;
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use opcua::client::{ClientBuilder, IdentityToken, MonitoredItemMap, OnSubscriptionNotificationCore, Session};
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    AttributeId, BrowseDescription, BrowseDirection, BrowseResultMask, DataChangeNotification, DataValue,
    MessageSecurityMode, MonitoredItemCreateRequest, MonitoringMode, MonitoringParameters, NodeClass, NodeClassMask,
    NodeId, NotificationMessage, ObjectId, QualifiedName, ReadValueId, ReferenceTypeId, StatusChangeNotification,
    StatusCode, TimestampsToReturn, Variant, WriteValue,
};
use tokio::task::JoinHandle;

const ROBOTICS: &str = "http://opcfoundation.org/UA/Robotics/";
const INSTANCES_SUFFIX: &str = ":instances";

struct Options {
    url: String,
    sessions: usize,
    seconds: u64,
    publishing_ms: u64,
    server_pid: Option<u32>,
}

/// `--encrypt USER`: Basic256Sha256 SignAndEncrypt as USER, the password read from the environment
/// variable `NODESET_LOAD_PASSWORD` (never from the command line); `None` uses SecurityPolicy None.
static ENCRYPT: std::sync::OnceLock<Option<(String, String)>> = std::sync::OnceLock::new();

fn options() -> Result<Options, String> {
    let mut o = Options { url: String::new(), sessions: 50, seconds: 300, publishing_ms: 100, server_pid: None };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--url" => o.url = value("--url")?,
            "--sessions" => o.sessions = value("--sessions")?.parse().map_err(|e| format!("--sessions: {e}"))?,
            "--seconds" => o.seconds = value("--seconds")?.parse().map_err(|e| format!("--seconds: {e}"))?,
            "--publishing-ms" => o.publishing_ms = value("--publishing-ms")?.parse().map_err(|e| format!("--publishing-ms: {e}"))?,
            "--server-pid" => o.server_pid = Some(value("--server-pid")?.parse().map_err(|e| format!("--server-pid: {e}"))?),
            "--encrypt" => {
                let user = value("--encrypt")?;
                let password = std::env::var("NODESET_LOAD_PASSWORD")
                    .map_err(|_| "--encrypt needs the password in the environment variable NODESET_LOAD_PASSWORD")?;
                let _ = ENCRYPT.set(Some((user, password)));
            }
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    if o.url.is_empty() {
        return Err("--url is required".into());
    }
    let host = o.url.trim_start_matches("opc.tcp://").split([':', '/']).next().unwrap_or_default();
    if !(host == "localhost" || host.starts_with("127.") || host == "[::1]") {
        return Err(format!("the load test only targets loopback addresses, not {host:?}"));
    }
    if o.sessions == 0 || o.seconds == 0 || o.publishing_ms == 0 {
        return Err("--sessions, --seconds and --publishing-ms must be at least 1".into());
    }
    Ok(o)
}

/// VmRSS of a process in KiB.
fn rss_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status.lines().find_map(|l| l.strip_prefix("VmRSS:")?.trim().strip_suffix("kB")?.trim().parse().ok())
}

/// What one session's subscription saw.
#[derive(Default, Debug)]
struct Seen {
    /// Data-change notifications (one per monitored item per NotificationMessage).
    notifications: u64,
    /// Of those, for the changing joint positions.
    joint_notifications: u64,
    /// NotificationMessages with data, and keep-alives.
    messages: u64,
    keep_alives: u64,
    /// Sequence numbers missing between consecutive NotificationMessages with data.
    gaps: u64,
    last_sequence: Option<u32>,
    /// Bad values, unknown client handles, status changes of the subscription.
    errors: Vec<String>,
}

struct Tracker {
    seen: Arc<Mutex<Seen>>,
    joints: Arc<HashSet<NodeId>>,
}

impl OnSubscriptionNotificationCore for Tracker {
    fn on_subscription_notification(&mut self, message: NotificationMessage, items: MonitoredItemMap<'_>) {
        let mut seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        let data = match message.notification_data {
            Some(d) if !d.is_empty() => d,
            _ => {
                seen.keep_alives += 1;
                return;
            }
        };
        seen.messages += 1;
        if let Some(last) = seen.last_sequence {
            let expected = last.wrapping_add(1);
            if message.sequence_number != expected {
                seen.gaps += u64::from(message.sequence_number.wrapping_sub(expected));
            }
        }
        seen.last_sequence = Some(message.sequence_number);
        for obj in data {
            if let Some(change) = obj.inner_as::<DataChangeNotification>() {
                for n in change.monitored_items.iter().flatten() {
                    seen.notifications += 1;
                    match items.get(n.client_handle) {
                        Some(item) => {
                            if self.joints.contains(&item.item_to_monitor().node_id) {
                                seen.joint_notifications += 1;
                            }
                        }
                        None => seen.errors.push(format!("a notification for unknown client handle {}", n.client_handle)),
                    }
                    let status = n.value.status();
                    if !status.is_good() {
                        seen.errors.push(format!("a value with status {status}"));
                    }
                }
            } else if let Some(change) = obj.inner_as::<StatusChangeNotification>() {
                seen.errors.push(format!("subscription status changed to {}", change.status));
            } else {
                seen.errors.push("a notification of an unexpected type".into());
            }
        }
    }
}

/// Connects a session. The first (`keypair`) creates the client's application keypair, the others reuse it.
async fn connect(url: &str, name: &str, keypair: bool) -> Result<(Arc<Session>, JoinHandle<StatusCode>), String> {
    let mut client = ClientBuilder::new()
        .application_name(format!("nodeset-models load {name}"))
        .application_uri(format!("urn:nodeset-models:load:{name}"))
        .pki_dir(std::env::temp_dir().join("nodeset-models-load-pki"))
        .create_sample_keypair(keypair)
        // A load tool on loopback: it trusts the server it was pointed at (the server still checks it).
        .trust_server_certs(true)
        .session_retry_limit(0)
        .session_timeout(60_000)
        .client()
        .map_err(|e| format!("client config: {e:?}"))?;
    let (policy, mode, identity) = match ENCRYPT.get() {
        Some(Some((user, password))) => (
            SecurityPolicy::Basic256Sha256,
            MessageSecurityMode::SignAndEncrypt,
            IdentityToken::new_user_name(user.clone(), opcua::client::Password::new(password.clone())),
        ),
        _ => (SecurityPolicy::None, MessageSecurityMode::None, IdentityToken::Anonymous),
    };
    let (session, event_loop) = client
        .connect_to_matching_endpoint((url, policy.to_str(), mode), identity)
        .await
        .map_err(|e| format!("{name}: cannot connect to {url}: {e}"))?;
    let event_loop = event_loop.spawn();
    match tokio::time::timeout(Duration::from_secs(20), session.wait_for_connection()).await {
        Ok(true) => {}
        _ => return Err(format!("{name}: the session did not connect")),
    }
    session.read_namespace_array().await.map_err(|e| format!("{name}: NamespaceArray: {e}"))?;
    Ok((session, event_loop))
}

/// The forward hierarchical children of a node: (NodeId, BrowseName, NodeClass).
async fn children(session: &Session, node: &NodeId) -> Result<Vec<(NodeId, QualifiedName, NodeClass)>, String> {
    let description = BrowseDescription {
        node_id: node.clone(),
        browse_direction: BrowseDirection::Forward,
        reference_type_id: ReferenceTypeId::HierarchicalReferences.into(),
        include_subtypes: true,
        node_class_mask: (NodeClassMask::OBJECT | NodeClassMask::VARIABLE).bits(),
        result_mask: BrowseResultMask::All as u32,
    };
    let result = session.browse(&[description], 0, None).await.map_err(|e| format!("browse {node}: {e}"))?;
    let result = result.into_iter().next().ok_or("an empty browse response")?;
    if !result.status_code.is_good() {
        return Err(format!("browse {node}: {}", result.status_code));
    }
    Ok(result
        .references
        .unwrap_or_default()
        .into_iter()
        .map(|r| (r.node_id.node_id, r.browse_name, r.node_class))
        .collect())
}

async fn child(session: &Session, node: &NodeId, name: &str) -> Result<NodeId, String> {
    children(session, node)
        .await?
        .into_iter()
        .find(|(_, b, _)| b.name.as_ref() == name)
        .map(|(id, _, _)| id)
        .ok_or_else(|| format!("{node} has no child {name}"))
}

/// Every variable under the robot's axes, and which of them are joint positions.
async fn axis_variables(session: &Session) -> Result<(Vec<NodeId>, HashSet<NodeId>, NodeId), String> {
    let objects: NodeId = ObjectId::ObjectsFolder.into();
    let robot = child(session, &objects, "Robot").await?;
    let arm = child(session, &child(session, &robot, "MotionDevices").await?, "Arm").await?;
    let axes = child(session, &arm, "Axes").await?;
    let mut variables = Vec::new();
    let mut joints = HashSet::new();
    let mut stack: Vec<NodeId> = children(session, &axes).await?.into_iter().map(|(id, _, _)| id).collect();
    let mut visited = HashSet::new();
    let mut listed = HashSet::new();
    while let Some(node) = stack.pop() {
        if !visited.insert(node.clone()) {
            continue;
        }
        for (id, name, class) in children(session, &node).await? {
            if class == NodeClass::Variable {
                if name.name.as_ref() == "ActualPosition" {
                    joints.insert(id.clone());
                }
                if listed.insert(id.clone()) {
                    variables.push(id.clone());
                }
            }
            stack.push(id);
        }
    }
    let controller = child(session, &child(session, &robot, "Controllers").await?, "Controller").await?;
    let stop_mode = child(
        session,
        &child(session, &child(session, &controller, "SystemOperation").await?, "SystemOperationStateMachine").await?,
        "ConfiguredDefaultStopMode",
    )
    .await?;
    Ok((variables, joints, stop_mode))
}

struct Subscriber {
    /// When its monitored items were created: notifications are expected from then on.
    since: Instant,
    session: Arc<Session>,
    event_loop: JoinHandle<StatusCode>,
    seen: Arc<Mutex<Seen>>,
}

async fn subscribe(
    url: &str,
    index: usize,
    variables: &[NodeId],
    joints: Arc<HashSet<NodeId>>,
    publishing: Duration,
) -> Result<Subscriber, String> {
    let name = format!("session {index}");
    let (session, event_loop) = connect(url, &name, false).await?;
    let seen = Arc::new(Mutex::new(Seen::default()));
    let tracker = Tracker { seen: seen.clone(), joints };
    let subscription = session
        .create_subscription(publishing, 600, 30, 0, 0, true, tracker)
        .await
        .map_err(|e| format!("{name}: create_subscription: {e}"))?;
    let items: Vec<MonitoredItemCreateRequest> = variables
        .iter()
        .map(|v| {
            MonitoredItemCreateRequest::new(
                ReadValueId { node_id: v.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() },
                MonitoringMode::Reporting,
                MonitoringParameters {
                    sampling_interval: publishing.as_secs_f64() * 1000.0,
                    queue_size: 10,
                    discard_oldest: true,
                    ..Default::default()
                },
            )
        })
        .collect();
    let created = session
        .create_monitored_items(subscription, TimestampsToReturn::Both, items)
        .await
        .map_err(|e| format!("{name}: create_monitored_items: {e}"))?;
    if let Some(bad) = created.iter().find(|c| !c.result.status_code.is_good()) {
        return Err(format!("{name}: a monitored item was refused: {}", bad.result.status_code));
    }
    Ok(Subscriber { since: Instant::now(), session, event_loop, seen })
}

/// Writes `ConfiguredDefaultStopMode` ten times a second until `until`, reading each value back.
async fn write_loop(url: String, node: NodeId, until: Instant) -> Result<(u64, Vec<String>), String> {
    let (session, event_loop) = connect(&url, "writer", false).await?;
    let mut writes = 0u64;
    let mut errors = Vec::new();
    let mut tick = tokio::time::interval(Duration::from_millis(100));
    let mut value: i16 = 0;
    while Instant::now() < until {
        tick.tick().await;
        value = (value + 1) % 3;
        let write = WriteValue {
            node_id: node.clone(),
            attribute_id: AttributeId::Value as u32,
            value: DataValue::value_only(Variant::Int16(value)),
            ..Default::default()
        };
        match session.write(&[write]).await {
            Ok(results) if results.first().is_some_and(|s| s.is_good()) => writes += 1,
            Ok(results) => errors.push(format!("write: {results:?}")),
            Err(e) => errors.push(format!("write: {e}")),
        }
        let read = ReadValueId { node_id: node.clone(), attribute_id: AttributeId::Value as u32, ..Default::default() };
        match session.read(&[read], TimestampsToReturn::Neither, 0.0).await {
            Ok(v) if v.first().and_then(|d| d.value.clone()) == Some(Variant::Int16(value)) => {}
            Ok(v) => errors.push(format!("read back {value}: {:?}", v.first().map(|d| &d.value))),
            Err(e) => errors.push(format!("read back: {e}")),
        }
    }
    let _ = session.disconnect().await;
    let _ = tokio::time::timeout(Duration::from_secs(5), event_loop).await;
    Ok((writes, errors))
}

/// The CPU time (user + system) a process has used, in seconds, from `/proc/PID/stat`.
fn cpu_seconds(pid: u32) -> Option<f64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The fields after the command name (which may hold spaces) start after the last ')'.
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    // USER_HZ is 100 on Linux.
    Some((utime + stime) / 100.0)
}

async fn run(o: Options) -> Result<bool, String> {
    let rss_start = o.server_pid.and_then(rss_kib);
    let publishing = Duration::from_millis(o.publishing_ms);
    let (probe, probe_loop) = connect(&o.url, "probe", true).await?;
    let ns = probe.read_namespace_array().await.map_err(|e| format!("namespace array: {e}"))?;
    if ns.get_index(ROBOTICS).is_none() || !ns.known_namespaces().keys().any(|u| u.ends_with(INSTANCES_SUFFIX)) {
        return Err(format!("{} does not serve the robot example", o.url));
    }
    let (variables, joints, stop_mode) = axis_variables(&probe).await?;
    let _ = probe.disconnect().await;
    let _ = tokio::time::timeout(Duration::from_secs(5), probe_loop).await;
    if joints.len() != 6 {
        return Err(format!("found {} joint positions, expected 6", joints.len()));
    }
    let joints = Arc::new(joints);
    eprintln!(
        "load: {} sessions, each subscribed to {} axis variables ({} joint positions) at {} ms, for {} s",
        o.sessions,
        variables.len(),
        joints.len(),
        o.publishing_ms,
        o.seconds
    );

    // Connect and subscribe all sessions, a few at a time.
    let mut subscribers = Vec::with_capacity(o.sessions);
    for chunk_start in (0..o.sessions).step_by(10) {
        let mut tasks = Vec::new();
        for i in chunk_start..(chunk_start + 10).min(o.sessions) {
            let (url, variables, joints) = (o.url.clone(), variables.clone(), joints.clone());
            tasks.push(tokio::spawn(async move { subscribe(&url, i, &variables, joints, publishing).await }));
        }
        for t in tasks {
            subscribers.push(t.await.map_err(|e| e.to_string())??);
        }
    }
    let rss_subscribed = o.server_pid.and_then(rss_kib);
    let cpu_start = o.server_pid.and_then(cpu_seconds);
    let started = Instant::now();
    let until = started + Duration::from_secs(o.seconds);
    let writer = tokio::spawn(write_loop(o.url.clone(), stop_mode, until));
    // Report progress every minute of a long run.
    while Instant::now() < until {
        tokio::time::sleep(until.saturating_duration_since(Instant::now()).min(Duration::from_secs(60))).await;
        if Instant::now() < until {
            let total: u64 = subscribers.iter().map(|s| s.seen.lock().unwrap_or_else(|e| e.into_inner()).notifications).sum();
            eprintln!("load: {:.0} s, {total} notifications so far", started.elapsed().as_secs_f64());
        }
    }
    let (writes, write_errors) = writer.await.map_err(|e| e.to_string())??;
    // One more publishing interval for the last notifications, then measure and close.
    tokio::time::sleep(publishing * 2).await;
    let elapsed = started.elapsed().as_secs_f64();
    let cpu = match (cpu_start, o.server_pid.and_then(cpu_seconds)) {
        (Some(a), Some(b)) => format!("{:.1}", 100.0 * (b - a) / elapsed),
        _ => "?".to_owned(),
    };
    let end = Instant::now();
    let rss_end = o.server_pid.and_then(rss_kib);

    let mut totals = Seen::default();
    let mut session_errors = Vec::new();
    let mut samples = 0u64;
    for (i, s) in subscribers.iter().enumerate() {
        // The value when the item was created, then one sample per interval.
        samples += 1 + (end.duration_since(s.since).as_secs_f64() * 1000.0 / o.publishing_ms as f64).floor() as u64;
        let seen = s.seen.lock().unwrap_or_else(|e| e.into_inner());
        totals.notifications += seen.notifications;
        totals.joint_notifications += seen.joint_notifications;
        totals.messages += seen.messages;
        totals.keep_alives += seen.keep_alives;
        totals.gaps += seen.gaps;
        session_errors.extend(seen.errors.iter().map(|e| format!("session {i}: {e}")));
    }
    for s in subscribers {
        let _ = s.session.disconnect().await;
        let _ = tokio::time::timeout(Duration::from_secs(5), s.event_loop).await;
    }
    let static_items = (variables.len() - joints.len()) as u64;
    let expected_joint = joints.len() as u64 * samples;
    let expected = expected_joint + o.sessions as u64 * static_items;
    let ratio = totals.notifications as f64 / expected as f64;
    let errors = session_errors.len() + write_errors.len();
    let kib = |v: Option<u64>| v.map_or("?".to_string(), |v| v.to_string());

    println!("sessions                  {}", o.sessions);
    println!("monitored items           {} per session ({} joint positions)", variables.len(), joints.len());
    println!("duration                  {elapsed:.1} s at a {} ms publishing interval", o.publishing_ms);
    println!("notifications received    {} ({} of joint positions)", totals.notifications, totals.joint_notifications);
    println!("notifications expected    {expected} ({expected_joint} of joint positions)  -> {:.1}% received", 100.0 * ratio);
    println!("notification messages     {} with data, {} keep-alives", totals.messages, totals.keep_alives);
    println!("sequence-number gaps      {}", totals.gaps);
    println!("writes (read back)        {writes}");
    println!("errors                    {errors}");
    for e in session_errors.iter().chain(&write_errors).take(20) {
        println!("  {e}");
    }
    println!(
        "server RSS                start {} KiB, subscribed {} KiB, end {} KiB",
        kib(rss_start),
        kib(rss_subscribed),
        kib(rss_end)
    );
    let security = if matches!(ENCRYPT.get(), Some(Some(_))) { "Basic256Sha256/SignAndEncrypt" } else { "None" };
    let rate = totals.notifications as f64 / elapsed;
    println!("security                  {security}");
    println!("notifications per second  {rate:.0}");
    println!("server CPU                {cpu}% of one core while subscribed");
    println!(
        "LOAD security={security} sessions={} items={} seconds={elapsed:.1} received={} expected={expected} ratio={ratio:.4} gaps={} errors={errors} \
         writes={writes} notifications_per_s={rate:.0} server_cpu_pct={cpu} rss_start_kib={} rss_subscribed_kib={} rss_end_kib={}",
        o.sessions,
        variables.len(),
        totals.notifications,
        totals.gaps,
        kib(rss_start),
        kib(rss_subscribed),
        kib(rss_end)
    );
    Ok(totals.gaps == 0 && errors == 0 && ratio >= 0.95 && writes > 0)
}

fn main() -> ExitCode {
    let filter = std::env::var("RUST_LOG").unwrap_or_else(|_| "warn,opcua_client=error,opcua_core=error,opcua_crypto=off".into());
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
    let o = match options() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let runtime = match tokio::runtime::Runtime::new() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: cannot start tokio: {e}");
            return ExitCode::FAILURE;
        }
    };
    match runtime.block_on(run(o)) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => {
            eprintln!("error: the load test failed (see the report)");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
