//! Who may do what: anonymous sessions read (on either endpoint), users from the
//! configuration log in on the signed and encrypted endpoint and may also write the
//! configured leaves. The password check is async-opcua's own authenticator; this one takes
//! the write right from anonymous sessions.

use opcua::server::address_space::AccessLevel;
use opcua::server::authenticator::{AuthManager, DefaultAuthenticator, Password, UserToken};
use opcua::server::{ServerEndpoint, ServerUserToken};
use opcua::types::{Error, NodeId, UserTokenPolicy};
use std::collections::BTreeMap;

/// Users by password, anonymous read-only.
pub struct Auth {
    inner: DefaultAuthenticator,
}

impl Auth {
    /// The users of the configuration (ids as the endpoints name them).
    pub fn new(users: BTreeMap<String, ServerUserToken>) -> Auth {
        Auth {
            inner: DefaultAuthenticator::new(users),
        }
    }
}

#[async_trait::async_trait]
impl AuthManager for Auth {
    async fn authenticate_anonymous_token(&self, endpoint: &ServerEndpoint) -> Result<(), Error> {
        self.inner.authenticate_anonymous_token(endpoint).await
    }

    async fn authenticate_username_identity_token(
        &self,
        endpoint: &ServerEndpoint,
        username: &str,
        password: &Password,
    ) -> Result<UserToken, Error> {
        let result = self
            .inner
            .authenticate_username_identity_token(endpoint, username, password)
            .await;
        if result.is_err() {
            crate::say!("login of `{username}` refused");
        }
        result
    }

    fn effective_user_access_level(
        &self,
        token: &UserToken,
        user_access_level: AccessLevel,
        _node_id: &NodeId,
    ) -> AccessLevel {
        if token.is_anonymous() {
            user_access_level - AccessLevel::CURRENT_WRITE
        } else {
            user_access_level
        }
    }

    fn user_token_policies(&self, endpoint: &ServerEndpoint) -> Vec<UserTokenPolicy> {
        self.inner.user_token_policies(endpoint)
    }
}
