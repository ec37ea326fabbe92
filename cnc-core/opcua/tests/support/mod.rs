//! What the server's tests share: a free port, a client session (anonymous without security,
//! or logged in over Basic256Sha256 SignAndEncrypt), and reads.

#![allow(dead_code)]

use opcua::client::{ClientBuilder, IdentityToken, Session};
use opcua::crypto::SecurityPolicy;
use opcua::types::{
    DataValue, MessageSecurityMode, NodeId, ReadValueId, TimestampsToReturn, UserTokenPolicy,
    Variant,
};
use std::sync::Arc;

/// A port no one listens on (the OS's choice).
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .unwrap()
}

/// How a session logs in.
#[derive(Debug, Clone, Copy)]
pub enum Login<'a> {
    /// Anonymous, security None.
    Anonymous,
    /// Anonymous over the encrypted endpoint.
    AnonymousSecure,
    /// A user over the encrypted endpoint.
    User(&'a str, &'a str),
}

/// A session to the server on `port` (certificates in `pki`), or `None` when the server
/// refused it (`retries` reconnection attempts first).
pub async fn try_connect(
    port: u16,
    pki: &std::path::Path,
    login: Login<'_>,
    retries: u32,
) -> Option<Arc<Session>> {
    let mut client = ClientBuilder::new()
        .application_name("cnc-opcua test client")
        .application_uri("urn:cnc-opcua-test-client")
        .pki_dir(pki)
        .create_sample_keypair(true)
        .trust_server_certs(true)
        .session_retry_limit(retries as i32)
        .client()
        .unwrap();
    let url = format!("opc.tcp://127.0.0.1:{port}/");
    let (policy, mode, identity) = match login {
        Login::Anonymous => (
            SecurityPolicy::None,
            MessageSecurityMode::None,
            IdentityToken::Anonymous,
        ),
        Login::AnonymousSecure => (
            SecurityPolicy::Basic256Sha256,
            MessageSecurityMode::SignAndEncrypt,
            IdentityToken::Anonymous,
        ),
        Login::User(name, password) => (
            SecurityPolicy::Basic256Sha256,
            MessageSecurityMode::SignAndEncrypt,
            IdentityToken::new_user_name(name, password),
        ),
    };
    let (session, event_loop) = client
        .connect_to_matching_endpoint(
            (
                url.as_str(),
                policy.to_str(),
                mode,
                UserTokenPolicy::anonymous(),
            ),
            identity,
        )
        .await
        .ok()?;
    let mut running = event_loop.spawn();
    // Connected, or the loop gave up (refused and out of retries).
    tokio::select! {
        connected = session.wait_for_connection() => connected.then_some(session),
        _ = &mut running => None,
    }
}

/// An anonymous session without security to the server on `port`, its certificates in `pki`.
pub async fn connect(port: u16, pki: &std::path::Path) -> Arc<Session> {
    try_connect(port, pki, Login::Anonymous, 20)
        .await
        .expect("connected")
}

/// One node's value attribute.
pub async fn read(session: &Session, id: &NodeId) -> DataValue {
    session
        .read(
            &[ReadValueId::from(id.clone())],
            TimestampsToReturn::Both,
            0.0,
        )
        .await
        .unwrap()
        .remove(0)
}

/// The index of the server's namespace, read from its namespace array.
pub async fn namespace(session: &Session) -> u16 {
    let id = NodeId::from(opcua::types::VariableId::Server_NamespaceArray);
    let value = read(session, &id).await.value;
    let Some(Variant::Array(array)) = value else {
        panic!("namespace array: {value:?}");
    };
    array
        .values
        .iter()
        .position(|v| matches!(v, Variant::String(s) if s.as_ref() == cnc_opcua::NAMESPACE))
        .expect("our namespace") as u16
}
