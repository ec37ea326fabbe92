//! An OPC UA server over the HLI image.
//!
//! It attaches to a running CNC's segment the way `plc watch` does (never the PLC slot, never
//! the tick) and serves every node of the image's symbol table under its ST path: structs and
//! arrays as folders, leaves as variables of the OPC UA type that matches their ST type, a
//! `_scaled` sibling in engineering units where the HLI unit is known, and summary objects
//! per machine, axis, channel and FIFO group. A value is read from the image when a client
//! reads it or a subscription samples it (leaf-wise atomic loads), dated by the CNC tick that
//! wrote it; while no CNC serves the image, values answer `BadNoCommunication`.
//!
//! Anonymous sessions read. Users of the configuration log in on the Basic256Sha256
//! SignAndEncrypt endpoint and may write the leaves the configuration opens, each write
//! checked by the handshake rules of `plc set`.

#![forbid(unsafe_code)]

pub mod auth;
pub mod config;
pub mod source;
pub mod space;
pub mod units;
pub mod value;

pub use config::{Config, ConfigError};
pub use source::{ImageSource, Instance};
pub use value::{data_type, variant};

use opcua::server::{
    ServerBuilder, ServerEndpoint, ServerHandle, ServerUserToken, ANONYMOUS_USER_TOKEN_ID,
};
use std::collections::{BTreeMap, HashSet};
use std::sync::Arc;

/// Writes one line to stderr, prefixed `cnc-opcua: `, through [`cnc_os::stdio::line_err`]:
/// a closed stderr is ignored (`eprintln!` would panic and end the task that logs, so that
/// a signal task could no longer stop the server).
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {
        cnc_os::stdio::line_err(&format!("cnc-opcua: {}", format_args!($($arg)*)))
    };
}

/// The namespace of the image's nodes.
pub const NAMESPACE: &str = "urn:cnc-plc-runtime:hli";

/// Data changes per publish message at most (about 35 bytes each: far below a message's
/// 327 KB limit).
pub const MAX_NOTIFICATIONS_PER_PUBLISH: u64 = 1_000;

/// Why the server could not be built.
#[derive(Debug)]
pub struct BuildError(pub String);

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "OPC UA server: {}", self.0)
    }
}

impl std::error::Error for BuildError {}

/// How to serve.
#[derive(Debug, Clone)]
pub struct Options {
    /// TCP port (all interfaces).
    pub port: u16,
    /// Certificate store folder (the configuration's `pki_dir` wins).
    pub pki_dir: std::path::PathBuf,
    /// The checked configuration.
    pub config: Config,
}

/// The endpoints: security None for anonymous reading, Basic256Sha256 SignAndEncrypt for
/// anonymous reading and for the users.
fn endpoints(builder: ServerBuilder, config: &Config) -> (ServerBuilder, Arc<auth::Auth>) {
    let anonymous = ANONYMOUS_USER_TOKEN_ID.to_string();
    let mut users = BTreeMap::new();
    let mut ids = vec![anonymous.clone()];
    let mut builder = builder;
    for (k, user) in config.users.iter().enumerate() {
        let id = format!("user{k}");
        let token = ServerUserToken::user_pass(user.name.as_str(), user.password.as_str());
        builder = builder.add_user_token(id.clone(), token.clone());
        users.insert(id.clone(), token);
        ids.push(id);
    }
    let builder = builder
        .add_endpoint("none", ServerEndpoint::new_none("/", &[anonymous]))
        .add_endpoint(
            "secure",
            ServerEndpoint::new_basic256sha256_sign_encrypt("/", &ids),
        );
    (builder, Arc::new(auth::Auth::new(users)))
}

/// The server `options` describe, its address space built from the symbol table and read
/// from `source`. Run it with `server.run().await`; the handle stops it (`cancel`).
pub fn build(
    source: Arc<dyn ImageSource>,
    options: &Options,
) -> Result<(opcua::server::Server, ServerHandle), BuildError> {
    let config = &options.config;
    let pki = config.pki_dir.clone().unwrap_or(options.pki_dir.clone());
    let mut builder = ServerBuilder::new()
        .application_name("cnc-plc-runtime HLI")
        .application_uri("urn:cnc-plc-runtime:opcua")
        .product_uri("urn:cnc-plc-runtime")
        .discovery_urls(vec!["/".to_owned()])
        .host("0.0.0.0")
        .port(options.port)
        .pki_dir(pki)
        .create_sample_keypair(config.certificate.is_none())
        .trust_client_certs(config.trust_client_certificates)
        .max_sessions(config.limits.max_sessions);
    if let (Some(cert), Some(key)) = (&config.certificate, &config.private_key) {
        builder = builder.certificate_path(cert).private_key_path(key);
    }
    let subs = &mut builder.limits_mut().subscriptions;
    subs.max_subscriptions_per_session = config.limits.max_subscriptions_per_session;
    subs.max_monitored_items_per_sub = config.limits.max_monitored_items_per_subscription;
    subs.min_sampling_interval_ms = config.limits.min_sampling_interval_ms;
    subs.min_publishing_interval_ms = config.limits.min_publishing_interval_ms;
    // Without a cap, one publish carries every queued sample of every item: 1,000 items
    // sampled ten times between publishes pass the 327 KB message limit of async-opcua's
    // defaults, and the message is lost whole. The notifications go out in messages of at
    // most this many.
    subs.max_notifications_per_publish = MAX_NOTIFICATIONS_PER_PUBLISH;
    let poll = config.limits.min_publishing_interval_ms.round() as u64;
    builder = builder.subscription_poll_interval_ms(poll);
    let (builder, auth) = endpoints(builder, config);
    let (server, handle) = builder
        .with_authenticator(auth)
        .with_node_manager(opcua::server::node_manager::memory::simple_node_manager(
            opcua::server::diagnostics::NamespaceMetadata {
                namespace_uri: NAMESPACE.to_owned(),
                ..Default::default()
            },
            "hli",
        ))
        .build()
        .map_err(BuildError)?;
    let manager = handle
        .node_managers()
        .get_of_type::<space::Manager>()
        .ok_or_else(|| BuildError("no node manager".into()))?;
    let ns = handle
        .get_namespace_index(NAMESPACE)
        .ok_or_else(|| BuildError("no namespace".into()))?;
    let (axes, channels) = configured(&*source);
    let writable: HashSet<String> = config.writable.iter().cloned().collect();
    let plan = space::Plan {
        ns,
        source: &source,
        writable: &writable,
        rotary: &config.rotary_axes,
        axes,
        channels,
    };
    space::populate(&manager, &plan);
    Ok((server, handle))
}

/// The axes and channels the CNC configured (0, 0 while none serves the image; the
/// header's counts are bounded by the image's arrays).
fn configured(source: &dyn ImageSource) -> (usize, usize) {
    use hli::layout::image::{HliSegmentHeader, HLI_MAX_AXES, HLI_MAX_CHANNELS};
    use hli::PlaceExt;
    let mut counts = (0, 0);
    source.with_image(&mut |memory| {
        let header: HliSegmentHeader = memory.place(0).read();
        counts = (
            (header.axis_count as usize).min(HLI_MAX_AXES),
            (header.channel_count as usize).min(HLI_MAX_CHANNELS),
        );
    });
    counts
}
