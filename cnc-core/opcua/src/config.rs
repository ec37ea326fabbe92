//! The server's configuration file (TOML, `--config FILE`): port, certificates, users, the
//! leaves a user may write, rotary axes and the session limits. Every key is checked when the
//! server starts; a bad one is refused with the file and the key.

use hli::access::Leaf;
use hli::desc::SymbolWriter;
use hli::layout::image::HLI_MAX_AXES;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The configuration (every key optional).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// TCP port (`--port` wins).
    pub port: Option<u16>,
    /// Folder of the certificate store (own certificate, trusted and rejected clients).
    pub pki_dir: Option<PathBuf>,
    /// The server's certificate (`.der` or `.pem`); with `private_key`. Without both, a
    /// self-signed one is made in `pki_dir` at the first start.
    pub certificate: Option<PathBuf>,
    /// The server's private key (PEM).
    pub private_key: Option<PathBuf>,
    /// Trust every client certificate (tests, commissioning). Otherwise a new client's
    /// certificate lands in `pki_dir/rejected` until moved to `pki_dir/trusted`.
    #[serde(default)]
    pub trust_client_certificates: bool,
    /// Users who may log in on the encrypted endpoint (and write).
    #[serde(default)]
    pub users: Vec<User>,
    /// ST paths of PLC-written leaves a logged-in user may write (handshake rules apply).
    #[serde(default)]
    pub writable: Vec<String>,
    /// Axis indices whose positions are degrees (the rest are millimetres).
    #[serde(default)]
    pub rotary_axes: Vec<usize>,
    /// Pin every thread of the server to this CPU (away from the CNC's `--rt-cpu`).
    pub cpu: Option<usize>,
    /// Session and subscription limits.
    #[serde(default)]
    pub limits: Limits,
}

/// A user with a password.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct User {
    /// Login name.
    pub name: String,
    /// Password.
    pub password: String,
}

/// What clients may open at most: a client that floods cannot make the server take more.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Limits {
    /// Sessions at once (all clients).
    pub max_sessions: usize,
    /// Subscriptions per session.
    pub max_subscriptions_per_session: usize,
    /// Monitored items per subscription.
    pub max_monitored_items_per_subscription: usize,
    /// The shortest sampling interval granted, ms (at least 1).
    pub min_sampling_interval_ms: f64,
    /// The shortest publishing interval granted, ms (at least 10): also how often the server
    /// looks whether a subscription is due.
    pub min_publishing_interval_ms: f64,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            max_sessions: 8,
            max_subscriptions_per_session: 4,
            max_monitored_items_per_subscription: 2_000,
            min_sampling_interval_ms: 1.0,
            min_publishing_interval_ms: 10.0,
        }
    }
}

/// A configuration refused: the file, the key, why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigError {
    /// The file (empty for a configuration not read from one).
    pub file: String,
    /// The key (`writable[2]`, `limits.max_sessions`).
    pub key: String,
    /// Why.
    pub message: String,
}

impl std::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}: {}", self.file, self.key, self.message)
    }
}

impl std::error::Error for ConfigError {}

impl Config {
    /// Reads and checks `path`.
    pub fn load(path: &Path) -> Result<Config, ConfigError> {
        let file = path.display().to_string();
        let error = |key: &str, message: String| ConfigError {
            file: file.clone(),
            key: key.into(),
            message,
        };
        let text = std::fs::read_to_string(path).map_err(|e| error("(file)", e.to_string()))?;
        let config: Config =
            toml::from_str(&text).map_err(|e| error("(syntax)", e.message().to_string()))?;
        config
            .check()
            .map_err(|(key, message)| error(&key, message))?;
        Ok(config)
    }

    /// Checks every key: `Err((key, why))` for the first bad one.
    pub fn check(&self) -> Result<(), (String, String)> {
        self.check_writable()?;
        self.check_users()?;
        self.check_certificate()?;
        for (k, &axis) in self.rotary_axes.iter().enumerate() {
            if axis >= HLI_MAX_AXES {
                return Err((
                    format!("rotary_axes[{k}]"),
                    format!("axis {axis} is not in the image (0..{HLI_MAX_AXES})"),
                ));
            }
        }
        self.limits.check()
    }

    fn check_writable(&self) -> Result<(), (String, String)> {
        for (k, path) in self.writable.iter().enumerate() {
            let key = format!("writable[{k}]");
            let leaf = Leaf::resolve(path).map_err(|e| (key.clone(), e.to_string()))?;
            if leaf.writer == SymbolWriter::Cnc {
                return Err((
                    key,
                    format!("`{path}` is written by the CNC: no client may"),
                ));
            }
            // The header's PLC side is the PLC's identity and liveness; drive and I/O leaves
            // are the field's. Only the PLC's own control leaves may be opened.
            let control = matches!(leaf.writer, SymbolWriter::Plc | SymbolWriter::Both);
            if path.starts_with("header.") || !control {
                let why = format!("`{path}` is not a PLC control leaf: no client may write it");
                return Err((key, why));
            }
        }
        if !self.writable.is_empty() && self.users.is_empty() {
            return Err((
                "users".into(),
                "writable leaves need a user to write them".into(),
            ));
        }
        Ok(())
    }

    fn check_users(&self) -> Result<(), (String, String)> {
        for (k, user) in self.users.iter().enumerate() {
            let key = format!("users[{k}]");
            if user.name.trim().is_empty() || user.password.is_empty() {
                return Err((key, "a user needs a name and a password".into()));
            }
            if self.users[..k].iter().any(|u| u.name == user.name) {
                return Err((key, format!("user `{}` twice", user.name)));
            }
        }
        Ok(())
    }

    fn check_certificate(&self) -> Result<(), (String, String)> {
        use opcua::crypto::CertificateStore;
        match (&self.certificate, &self.private_key) {
            (None, None) => Ok(()),
            (Some(cert), Some(key)) => {
                CertificateStore::read_cert(cert)
                    .map_err(|e| ("certificate".into(), format!("{}: {e}", cert.display())))?;
                CertificateStore::read_pkey(key)
                    .map_err(|e| ("private_key".into(), format!("{}: {e}", key.display())))?;
                Ok(())
            }
            (Some(_), None) => Err(("private_key".into(), "a certificate needs its key".into())),
            (None, Some(_)) => Err(("certificate".into(), "a key needs its certificate".into())),
        }
    }
}

impl Limits {
    fn check(&self) -> Result<(), (String, String)> {
        let counts = [
            ("limits.max_sessions", self.max_sessions, 64),
            (
                "limits.max_subscriptions_per_session",
                self.max_subscriptions_per_session,
                64,
            ),
            (
                "limits.max_monitored_items_per_subscription",
                self.max_monitored_items_per_subscription,
                100_000,
            ),
        ];
        for (key, value, most) in counts {
            if value == 0 || value > most {
                return Err((key.into(), format!("{value} is not in 1..={most}")));
            }
        }
        let intervals = [
            (
                "limits.min_sampling_interval_ms",
                self.min_sampling_interval_ms,
                1.0,
            ),
            (
                "limits.min_publishing_interval_ms",
                self.min_publishing_interval_ms,
                10.0,
            ),
        ];
        for (key, ms, least) in intervals {
            if !ms.is_finite() || !(least..=60_000.0).contains(&ms) {
                return Err((key.into(), format!("{ms} is not in {least}..=60000")));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parsed(text: &str) -> Result<(), (String, String)> {
        let config: Config =
            toml::from_str(text).map_err(|e| ("(syntax)".into(), e.to_string()))?;
        config.check()
    }

    fn key_of(text: &str) -> String {
        parsed(text).expect_err(text).0
    }

    #[test]
    fn a_good_configuration_passes_and_bad_keys_are_named() {
        let good = "port = 4841\nwritable = ['gpCh[0]^channel_mc_control.path_override.feed_override_w']\n[[users]]\nname = 'op'\npassword = 'pw'\n";
        assert_eq!(parsed(good), Ok(()));
        assert_eq!(
            key_of("writable = ['gpAx[0]^nope']\n[[users]]\nname='a'\npassword='b'"),
            "writable[0]"
        );
        let cnc_owned = "writable = ['gpAx[0]^lr_state.current_position_acs_r']\n[[users]]\nname='a'\npassword='b'";
        assert_eq!(key_of(cnc_owned), "writable[0]");
        let liveness = "writable = ['header.plc_heartbeat']\n[[users]]\nname='a'\npassword='b'";
        assert!(parsed(liveness)
            .unwrap_err()
            .1
            .contains("not a PLC control leaf"));
        assert!(parsed(cnc_owned)
            .unwrap_err()
            .1
            .contains("written by the CNC"));
        assert_eq!(
            key_of("writable = ['gpCh[0]^channel_mc_control.path_override.feed_hold_w']"),
            "users"
        );
        assert_eq!(key_of("[[users]]\nname='a'\npassword=''"), "users[0]");
        assert_eq!(
            key_of("[[users]]\nname='a'\npassword='x'\n[[users]]\nname='a'\npassword='y'"),
            "users[1]"
        );
        assert_eq!(
            key_of("certificate = '/nonexistent/cert.der'\nprivate_key = '/nonexistent/key.pem'"),
            "certificate"
        );
        assert_eq!(
            key_of("certificate = '/nonexistent/cert.der'"),
            "private_key"
        );
        assert_eq!(key_of("rotary_axes = [32]"), "rotary_axes[0]");
        assert_eq!(key_of("[limits]\nmax_sessions = 0"), "limits.max_sessions");
        assert_eq!(
            key_of("[limits]\nmin_sampling_interval_ms = 0.5"),
            "limits.min_sampling_interval_ms"
        );
        assert_eq!(key_of("prot = 1"), "(syntax)");
    }

    #[test]
    fn a_file_is_named_in_its_refusal() {
        let dir = std::env::temp_dir().join(format!("cnc-opcua-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("bad.toml");
        std::fs::write(&path, "[limits]\nmax_sessions = 1000\n").unwrap();
        let e = Config::load(&path).unwrap_err();
        assert_eq!(e.key, "limits.max_sessions");
        assert!(
            e.to_string().starts_with(&path.display().to_string()),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
