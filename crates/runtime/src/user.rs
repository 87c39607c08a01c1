//! Users by uid and name, for ownership checks and for messages that say whose a file is.

use anyhow::{Result, anyhow};

/// The effective user id of this process: the user whose files a deployment may trust.
pub fn effective_uid() -> u32 {
    // SAFETY: geteuid has no preconditions and cannot fail.
    unsafe { libc::geteuid() }
}

/// The uid of `spec`: a number, or a user name looked up in the user database.
pub fn resolve(spec: &str) -> Result<u32> {
    let spec = spec.trim();
    if let Ok(uid) = spec.parse::<u32>() {
        return Ok(uid);
    }
    uid_of_name(spec).ok_or_else(|| anyhow!("{spec:?}: no such user (give a user name or a uid)"))
}

/// `name (uid N)` when the user database knows the uid, else `uid N`.
pub fn describe(uid: u32) -> String {
    match name_of_uid(uid) {
        Some(name) => format!("{name} (uid {uid})"),
        None => format!("uid {uid}"),
    }
}

/// Size of the scratch buffer the reentrant user-database calls fill (names, home, shell).
const PASSWD_BUFFER: usize = 4096;

fn uid_of_name(name: &str) -> Option<u32> {
    let c_name = std::ffi::CString::new(name).ok()?;
    // SAFETY: a zeroed passwd is a valid out-parameter; getpwnam_r writes into it and into `buf`,
    // both of which outlive the call, and sets `result` to null or to `&pwd`.
    unsafe {
        let mut pwd: libc::passwd = std::mem::zeroed();
        let mut buf = [0 as libc::c_char; PASSWD_BUFFER];
        let mut result: *mut libc::passwd = std::ptr::null_mut();
        let rc = libc::getpwnam_r(
            c_name.as_ptr(),
            &mut pwd,
            buf.as_mut_ptr(),
            buf.len(),
            &mut result,
        );
        (rc == 0 && !result.is_null()).then_some(pwd.pw_uid)
    }
}

fn name_of_uid(uid: u32) -> Option<String> {
    // SAFETY: as in `uid_of_name`; `pw_name` points into `buf` and is read before `buf` is dropped.
    unsafe {
        let mut pwd: libc::passwd = std::mem::zeroed();
        let mut buf = [0 as libc::c_char; PASSWD_BUFFER];
        let mut result: *mut libc::passwd = std::ptr::null_mut();
        let rc = libc::getpwuid_r(uid, &mut pwd, buf.as_mut_ptr(), buf.len(), &mut result);
        if rc != 0 || result.is_null() || pwd.pw_name.is_null() {
            return None;
        }
        Some(
            std::ffi::CStr::from_ptr(pwd.pw_name)
                .to_string_lossy()
                .into_owned(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_names_resolve_to_the_same_uid() {
        assert_eq!(resolve("0").unwrap(), 0);
        assert_eq!(resolve(" 65534 ").unwrap(), 65534);
        // root is in every user database.
        assert_eq!(resolve("root").unwrap(), 0);
        assert_eq!(describe(0), "root (uid 0)");
        let err = resolve("no-such-user-rins").unwrap_err().to_string();
        assert!(
            err.contains("no-such-user-rins") && err.contains("no such user"),
            "{err}"
        );
    }

    #[test]
    fn an_unknown_uid_is_described_by_number() {
        assert_eq!(describe(3_999_999_999), "uid 3999999999");
    }
}
