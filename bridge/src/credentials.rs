//! The credentials of runs across hosts: a certificate authority the user makes once
//! (`uio-launcher agent init`), a certificate for agents (and the workers they start) and one for
//! launchers. Links are mutual TLS: an agent admits only peers whose certificate that CA signed,
//! and a launcher talks only to an agent whose certificate it signed. The certificates' common
//! names are the peers' roles, which the agent's access rules ([`crate::access`]) tell apart.
//!
//! A directory holds `ca.pem` (and `ca.key`, needed only to make more certificates),
//! `agent.pem`/`agent.key` and `launcher.pem`/`launcher.key`. The agent's host needs `ca.pem`
//! and the agent's pair, the launcher's host `ca.pem` and the launcher's pair. Keys are 0600;
//! the folder and every file must be the user's and writable by nobody else, or they are
//! refused. Every agent has the same certificate: an agent's host that is compromised can pose
//! as any agent (make a CA per rig where that matters). A launcher's certificate is good only
//! for connecting, so it cannot pose as an agent.

use std::fs;
use std::io::Write;
use std::os::unix::fs::{DirBuilderExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

use rcgen::{
    BasicConstraints, CertificateParams, CertifiedIssuer, DnType, ExtendedKeyUsagePurpose, IsCa,
    KeyPair, KeyUsagePurpose,
};

/// Environment variable naming the credentials directory.
pub const ENV: &str = "UIO_CREDENTIALS";

/// The common name of agents' (and their workers') certificates.
pub const AGENT_CN: &str = "uio-agent";

/// The common name of launchers' certificates.
pub const LAUNCHER_CN: &str = "uio-launcher";

/// Which side's certificate a session presents.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Side {
    /// The agent and its workers.
    Agent,
    /// The launcher's proxies.
    Launcher,
}

impl Side {
    fn stem(self) -> &'static str {
        match self {
            Side::Agent => "agent",
            Side::Launcher => "launcher",
        }
    }
}

/// The files one side's TLS sessions use.
#[derive(Clone, Debug)]
pub struct Credentials {
    /// The CA every peer's certificate must chain to.
    pub ca: PathBuf,
    /// This side's certificate.
    pub cert: PathBuf,
    /// Its private key.
    pub key: PathBuf,
}

/// `$UIO_CREDENTIALS`, else `$XDG_CONFIG_HOME/uio-observers/credentials`, else
/// `~/.config/uio-observers/credentials`.
pub fn default_dir() -> PathBuf {
    if let Some(d) = std::env::var_os(ENV).filter(|d| !d.is_empty()) {
        return PathBuf::from(d);
    }
    let config = std::env::var_os("XDG_CONFIG_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(std::env::var_os("HOME").unwrap_or_else(|| "/".into())).join(".config")
        });
    config.join("uio-observers").join("credentials")
}

/// One side's credentials in `dir`, checked: every file present, regular, the key owned by us
/// and readable by us only.
pub fn load(dir: &Path, side: Side) -> Result<Credentials, String> {
    let c = Credentials {
        ca: dir.join("ca.pem"),
        cert: dir.join(format!("{}.pem", side.stem())),
        key: dir.join(format!("{}.key", side.stem())),
    };
    // SAFETY: geteuid has no preconditions.
    let me = unsafe { libc::geteuid() };
    // Whoever could write the folder or a certificate could swap in a CA of their own.
    let d = fs::symlink_metadata(dir).map_err(|e| {
        format!(
            "{}: {e} (make the credentials with `uio-launcher agent init`)",
            dir.display()
        )
    })?;
    if !d.file_type().is_dir() || d.uid() != me || d.mode() & 0o022 != 0 {
        return Err(format!(
            "{}: the credentials folder must be a real directory of this user that others cannot write (mode {:o}, owner {})",
            dir.display(),
            d.mode() & 0o777,
            d.uid()
        ));
    }
    for f in [&c.ca, &c.cert, &c.key] {
        let m = fs::symlink_metadata(f).map_err(|e| {
            format!(
                "{}: {e} (make the credentials with `uio-launcher agent init`)",
                f.display()
            )
        })?;
        if !m.file_type().is_file() || m.uid() != me || m.mode() & 0o022 != 0 {
            return Err(format!(
                "{}: must be a regular file of this user that others cannot write (mode {:o}, owner {})",
                f.display(),
                m.mode() & 0o777,
                m.uid()
            ));
        }
    }
    let m = fs::symlink_metadata(&c.key).map_err(|e| format!("{}: {e}", c.key.display()))?;
    if m.mode() & 0o077 != 0 {
        return Err(format!(
            "{}: a private key must be owned by this user with mode 0600 (it is {:o})",
            c.key.display(),
            m.mode() & 0o777
        ));
    }
    Ok(c)
}

/// Makes a CA and the agent's and the launcher's certificates in `dir` (created 0700). Refuses
/// to replace existing credentials unless `force`.
pub fn init(dir: &Path, force: bool) -> Result<(), String> {
    let err = |e: rcgen::Error| format!("cannot make a certificate: {e}");
    if !force && dir.join("ca.pem").exists() {
        return Err(format!(
            "{} already holds credentials (--force replaces them, and every host then needs the new ones)",
            dir.display()
        ));
    }
    fs::DirBuilder::new()
        .recursive(true)
        .mode(0o700)
        .create(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?;
    // Opened without following a link and checked as ours before its mode is set: a link or a
    // folder of another user planted at `dir` must not get root's chmod or root's keys.
    let opened = fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_DIRECTORY)
        .open(dir);
    let folder = opened.map_err(|e| {
        format!(
            "{}: not a real directory ({e}); refusing to write credentials there",
            dir.display()
        )
    })?;
    // SAFETY: geteuid has no preconditions.
    let me = unsafe { libc::geteuid() };
    let owner = folder
        .metadata()
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .uid();
    if owner != me {
        return Err(format!(
            "{}: belongs to uid {owner}, not to this user ({me}); refusing to write credentials there",
            dir.display()
        ));
    }
    folder
        .set_permissions(fs::Permissions::from_mode(0o700))
        .map_err(|e| format!("{}: {e}", dir.display()))?;

    let mut ca = CertificateParams::new(Vec::<String>::new()).map_err(err)?;
    ca.distinguished_name
        .push(DnType::CommonName, "uio-observers CA");
    ca.is_ca = IsCa::Ca(BasicConstraints::Constrained(0));
    ca.key_usages = vec![
        KeyUsagePurpose::KeyCertSign,
        KeyUsagePurpose::CrlSign,
        KeyUsagePurpose::DigitalSignature,
    ];
    let ca_key = KeyPair::generate().map_err(err)?;
    let ca_key_pem = ca_key.serialize_pem();
    let issuer = CertifiedIssuer::self_signed(ca, ca_key).map_err(err)?;
    write(&dir.join("ca.key"), &ca_key_pem, 0o600)?;
    write(&dir.join("ca.pem"), &issuer.pem(), 0o644)?;
    for (side, cn) in [(Side::Agent, AGENT_CN), (Side::Launcher, LAUNCHER_CN)] {
        // An agent's certificate serves (the agent) and connects (its workers); a launcher's
        // only connects, so a launcher's credential cannot pose as an agent to another launcher.
        let mut p = CertificateParams::new(vec![cn.to_string()]).map_err(err)?;
        p.distinguished_name.push(DnType::CommonName, cn);
        p.extended_key_usages = match side {
            Side::Agent => vec![
                ExtendedKeyUsagePurpose::ServerAuth,
                ExtendedKeyUsagePurpose::ClientAuth,
            ],
            Side::Launcher => vec![ExtendedKeyUsagePurpose::ClientAuth],
        };
        p.key_usages = vec![KeyUsagePurpose::DigitalSignature];
        let key = KeyPair::generate().map_err(err)?;
        let cert = p.signed_by(&key, &issuer).map_err(err)?;
        write(
            &dir.join(format!("{}.key", side.stem())),
            &key.serialize_pem(),
            0o600,
        )?;
        write(
            &dir.join(format!("{}.pem", side.stem())),
            &cert.pem(),
            0o644,
        )?;
    }
    Ok(())
}

/// Writes a file whole with `mode` from its creation (a key is never readable by others, not
/// even for an instant), replacing what was there.
fn write(path: &Path, text: &str, mode: u32) -> Result<(), String> {
    let tmp = path.with_extension("new");
    let _ = fs::remove_file(&tmp);
    let mut f = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(mode)
        .custom_flags(libc::O_NOFOLLOW)
        .open(&tmp)
        .map_err(|e| format!("{}: {e}", tmp.display()))?;
    f.write_all(text.as_bytes())
        .and_then(|_| f.sync_all())
        .map_err(|e| format!("{}: {e}", tmp.display()))?;
    fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    #[test]
    fn init_refuses_a_link_and_a_folder_of_another_user() {
        let base = std::env::temp_dir().join(format!("creds-planted-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir_all(base.join("target")).unwrap();
        std::os::unix::fs::symlink(base.join("target"), base.join("link")).unwrap();
        let e = super::init(&base.join("link"), false).unwrap_err();
        assert!(e.contains("not a real directory"), "{e}");
        assert!(!base.join("target/ca.pem").exists());
        if unsafe { libc::geteuid() } == 0 {
            let other = base.join("other");
            std::fs::create_dir(&other).unwrap();
            std::os::unix::fs::chown(&other, Some(65534), Some(65534)).unwrap();
            let e = super::init(&other, false).unwrap_err();
            assert!(e.contains("belongs to uid 65534"), "{e}");
            assert!(!other.join("ca.pem").exists());
        }
        std::fs::remove_dir_all(&base).unwrap();
    }

    use super::*;

    #[test]
    fn init_makes_loadable_private_credentials_once() {
        let dir = std::env::temp_dir().join(format!("uio-cred-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        init(&dir, false).unwrap();
        for side in [Side::Agent, Side::Launcher] {
            let c = load(&dir, side).unwrap();
            assert!(
                fs::read_to_string(&c.cert)
                    .unwrap()
                    .starts_with("-----BEGIN CERTIFICATE-----")
            );
            assert_eq!(fs::metadata(&c.key).unwrap().mode() & 0o777, 0o600);
        }
        assert_eq!(fs::metadata(&dir).unwrap().mode() & 0o777, 0o700);
        assert!(
            init(&dir, false)
                .unwrap_err()
                .contains("already holds credentials")
        );
        fs::set_permissions(dir.join("agent.key"), fs::Permissions::from_mode(0o644)).unwrap();
        assert!(load(&dir, Side::Agent).unwrap_err().contains("mode 0600"));
        init(&dir, true).unwrap();
        assert!(load(&dir, Side::Agent).is_ok());
        fs::set_permissions(dir.join("ca.pem"), fs::Permissions::from_mode(0o666)).unwrap();
        assert!(
            load(&dir, Side::Launcher)
                .unwrap_err()
                .contains("others cannot write")
        );
        fs::set_permissions(dir.join("ca.pem"), fs::Permissions::from_mode(0o644)).unwrap();
        fs::set_permissions(&dir, fs::Permissions::from_mode(0o777)).unwrap();
        assert!(
            load(&dir, Side::Launcher)
                .unwrap_err()
                .contains("credentials folder")
        );
        let _ = fs::remove_dir_all(&dir);
        assert!(
            load(&dir, Side::Launcher)
                .unwrap_err()
                .contains("uio-launcher agent init")
        );
    }
}
