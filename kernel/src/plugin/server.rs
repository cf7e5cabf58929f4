//! The child process side: `pilgrim plugin-server LIB SYMBOL` opens the
//! library, calls its entry and answers the host's requests
//! (`plugin::wire`) until the host closes the pipe.
//!
//! Before anything of the library runs, the protocol moves off the standard
//! streams (a plugin that prints to standard output cannot garble it: its
//! output goes to the error stream, which the host reads), core dumps are
//! turned off (a crash leaves no file in the user's directory) and the
//! process's address space is bounded ([`MAX_MEMORY`]): a plugin can end or
//! exhaust only this process.

use super::table::Table;
use super::wire::{self, TableHeader};
use super::Calls;
use pilgrim_plugin_abi::{EntryFn, NO_ROW, STATUS_ERROR, STATUS_OK};
use std::fs::File;
use std::io::Write;
use std::path::Path;

/// The most memory (address space, bytes) the child process may map.
pub const MAX_MEMORY: u64 = 8 << 30;

/// Moves the protocol off fds 0 and 1 (to descriptors closed on exec), puts
/// `/dev/null` on 0 and the error stream on 1, turns core dumps off and
/// bounds memory. Returns the protocol's input and output.
fn isolate() -> std::io::Result<(File, File)> {
    use std::os::fd::FromRawFd;
    // SAFETY: plain descriptor calls on this process's own descriptors;
    // each result is checked, and the new descriptors are owned below.
    unsafe {
        let input = libc::fcntl(0, libc::F_DUPFD_CLOEXEC, 3);
        let output = libc::fcntl(1, libc::F_DUPFD_CLOEXEC, 3);
        if input < 0 || output < 0 {
            return Err(std::io::Error::last_os_error());
        }
        let null = libc::open(c"/dev/null".as_ptr(), libc::O_RDONLY);
        if null < 0 || libc::dup2(null, 0) < 0 || libc::dup2(2, 1) < 0 {
            return Err(std::io::Error::last_os_error());
        }
        libc::close(null);
        let no_core = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        libc::setrlimit(libc::RLIMIT_CORE, &no_core);
        let memory = libc::rlimit {
            rlim_cur: MAX_MEMORY as libc::rlim_t,
            rlim_max: MAX_MEMORY as libc::rlim_t,
        };
        libc::setrlimit(libc::RLIMIT_AS, &memory);
        Ok((File::from_raw_fd(input), File::from_raw_fd(output)))
    }
}

/// Serves the plugin `lib` (entry `symbol`) on the standard streams; the
/// process's exit code.
pub fn serve(lib: &Path, symbol: &str) -> i32 {
    let Ok((mut input, mut output)) = isolate() else {
        return 3;
    };
    if output
        .write_all(wire::HELLO)
        .and_then(|_| output.flush())
        .is_err()
    {
        return 3;
    }
    let say = |output: &mut File, kind: u32, bytes: &[u8]| {
        wire::write_frame(output, kind, &[bytes]).is_ok()
    };
    // SAFETY: loading runs the library's initialisers: this process exists
    // to take whatever they do.
    let library = match unsafe { libloading::Library::new(lib) } {
        Ok(l) => l,
        Err(e) => {
            use std::error::Error as _;
            let message = match e.source() {
                Some(reason) => format!("{e}: {reason}"),
                None => e.to_string(),
            };
            say(&mut output, wire::OPEN_FAILED, message.as_bytes());
            return 0;
        }
    };
    // SAFETY: the symbol's type is the ABI's entry type.
    let entry: EntryFn = match unsafe { library.get::<EntryFn>(symbol.as_bytes()) } {
        Ok(f) => *f,
        Err(_) => {
            say(&mut output, wire::NO_ENTRY, symbol.as_bytes());
            return 0;
        }
    };
    // The library stays loaded for the life of this process.
    std::mem::forget(library);
    // SAFETY: calling the plugin's entry, which takes no arguments, and
    // reading the table it returns as the ABI lays it out.
    let Some((table, header)) = (unsafe { Table::read(entry()) }) else {
        say(&mut output, wire::NULL_TABLE, &[]);
        return 0;
    };
    if !say(&mut output, wire::LOADED, &header.encode()) {
        return 3;
    }
    answer(&table, &header, &mut input, &mut output)
}

/// Answers requests until the host closes its end.
fn answer(table: &Table, header: &TableHeader, input: &mut File, output: &mut File) -> i32 {
    loop {
        let (kind, bytes) = match wire::read_frame(input) {
            Ok(Some(f)) => f,
            Ok(None) => return 0,
            Err(_) => return 3,
        };
        let result = if header.major != pilgrim_plugin_abi::ABI_MAJOR {
            Err((
                NO_ROW,
                "the host does not call a plugin of another ABI major".into(),
            ))
        } else {
            handle(table, kind, &bytes)
        };
        let sent = match result {
            Ok(b) => wire::write_frame(output, STATUS_OK as u32, &[&b]),
            Err((row, message)) => wire::write_frame(
                output,
                STATUS_ERROR as u32,
                &[&wire::failure(row, &message)],
            ),
        };
        if sent.is_err() {
            return 3;
        }
    }
}

/// One request's answer: its bytes, or the failed row and the message.
fn handle(table: &Table, kind: u32, bytes: &[u8]) -> Result<Vec<u8>, (usize, String)> {
    let fail = |e: super::CallError| (e.row.unwrap_or(NO_ROW), e.message);
    let bad = || (NO_ROW, "a request the server cannot read".to_owned());
    match kind {
        wire::DESCRIBE => table.describe().map(String::into_bytes).map_err(fail),
        wire::INVERSE => {
            let (count, width, tool, poses) = wire::parse_batch(bytes, |_| 6).ok_or_else(bad)?;
            let mut out = vec![0.0; count.checked_mul(width).ok_or_else(bad)?];
            table
                .inverse(&poses, &tool, width, &mut out)
                .map_err(fail)?;
            Ok(wire::floats_to_bytes(&out))
        }
        wire::FORWARD => {
            let (count, width, tool, axes) = wire::parse_batch(bytes, |w| w).ok_or_else(bad)?;
            let mut out = vec![0.0; count.checked_mul(6).ok_or_else(bad)?];
            table.forward(&axes, &tool, width, &mut out).map_err(fail)?;
            Ok(wire::floats_to_bytes(&out))
        }
        wire::POST => table.post(bytes).map(String::into_bytes).map_err(fail),
        _ => Err(bad()),
    }
}
