//! What the server's tests share: a free port and an anonymous client session.

use opcua::client::{ClientBuilder, IdentityToken, Session};
use opcua::crypto::SecurityPolicy;
use opcua::types::{MessageSecurityMode, UserTokenPolicy};
use std::sync::Arc;

/// A port no one listens on (the OS's choice).
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .unwrap()
}

/// An anonymous session without security to the server on `port`, its certificates in `pki`.
pub async fn connect(port: u16, pki: &std::path::Path) -> Arc<Session> {
    let mut client = ClientBuilder::new()
        .application_name("cnc-opcua test client")
        .application_uri("urn:cnc-opcua-test-client")
        .pki_dir(pki)
        .create_sample_keypair(true)
        .trust_server_certs(true)
        .session_retry_limit(20)
        .client()
        .unwrap();
    let url = format!("opc.tcp://127.0.0.1:{port}/");
    let (session, event_loop) = client
        .connect_to_matching_endpoint(
            (
                url.as_str(),
                SecurityPolicy::None.to_str(),
                MessageSecurityMode::None,
                UserTokenPolicy::anonymous(),
            ),
            IdentityToken::Anonymous,
        )
        .await
        .unwrap();
    event_loop.spawn();
    assert!(session.wait_for_connection().await, "connected");
    session
}
