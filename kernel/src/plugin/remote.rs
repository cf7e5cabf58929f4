//! The host side of a plugin library loaded in a child process
//! (`pilgrim plugin-server`, [`super::server`]): whatever the library does
//! (crash, abort, exit, loop, print), the host sees a clear error naming
//! the library and what it did, within a time bound, and goes on.
//!
//! Every wait on the child has a deadline: loading ([`Bounds::load`]) and
//! each call ([`Bounds::call`], and never past the run's own limit,
//! [`crate::budget`]). A child past its deadline is killed. A child that
//! ends is waited for and its end told: the signal (a crash, an abort) or
//! the exit status, and the last lines it wrote to its error stream,
//! quoted short. After that every call fails at once with the same
//! message: a plugin is not restarted behind the user's back.

use super::wire::{self, TableHeader};
use super::{CallError, Calls};
use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::{AsRawFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex, RwLock};
use std::time::{Duration, Instant};

/// The time bounds of a plugin's child process.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Starting the process, loading the library and reading its table.
    pub load: Duration,
    /// Each call (a batch of kinematics, a descriptor, a post).
    pub call: Duration,
}

impl Default for Bounds {
    /// 30 seconds each.
    fn default() -> Self {
        Self {
            load: Duration::from_secs(30),
            call: Duration::from_secs(30),
        }
    }
}

/// What the child does before it answers its first call.
const LOADING: &str = "loading (its initialisation code and its entry)";

/// The most rows of one kinematics call (a longer batch is sent in
/// pieces, each bounded in time).
pub const CHUNK_ROWS: usize = 16_384;

static SETTINGS: RwLock<Option<(PathBuf, Bounds)>> = RwLock::new(None);

/// Sets the program that serves plugins in child processes (the `pilgrim`
/// executable: `pilgrim plugin-server`) and the time bounds. Unset, the
/// running executable serves, with [`Bounds::default`].
pub fn configure(program: Option<PathBuf>, bounds: Bounds) {
    let program = program.or_else(|| std::env::current_exe().ok());
    if let (Ok(mut s), Some(p)) = (SETTINGS.write(), program) {
        *s = Some((p, bounds));
    }
}

/// The server program and the bounds.
fn settings() -> Result<(PathBuf, Bounds), String> {
    if let Some(s) = SETTINGS.read().ok().and_then(|s| s.clone()) {
        return Ok(s);
    }
    std::env::current_exe()
        .map(|p| (p, Bounds::default()))
        .map_err(|e| format!("the program to load plugins in cannot be found: {e}"))
}

/// How loading in the child went, when it did not.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum StartError {
    /// The system could not open the library: its message.
    Open(String),
    /// The entry symbol is missing.
    NoEntry,
    /// The entry returned a null table.
    NullTable,
    /// The process crashed, ended, hung or could not start: what happened.
    Process(String),
}

/// The last bytes a child wrote to its error stream.
#[derive(Debug, Default)]
struct Tail {
    bytes: Vec<u8>,
    done: bool,
}

const TAIL_BYTES: usize = 4096;

/// A running child and its pipes.
#[derive(Debug)]
struct State {
    child: Child,
    to: File,
    from: File,
    tail: Arc<Mutex<Tail>>,
    /// Why the child is gone, once it is.
    gone: Option<String>,
}

/// A plugin library in a child process.
#[derive(Debug)]
pub(super) struct Remote {
    library: String,
    bounds: Bounds,
    state: Mutex<State>,
}

/// What stopped a wait.
enum Stop {
    /// The child's end closed (it ended).
    Closed,
    /// The deadline passed.
    Late,
    /// Another failure of the pipe.
    Io(std::io::Error),
}

/// Makes `fd` non-blocking.
fn non_blocking(fd: &impl AsRawFd) -> std::io::Result<()> {
    let fd = fd.as_raw_fd();
    // SAFETY: reading and setting the flags of a descriptor this process owns.
    let r = unsafe {
        let flags = libc::fcntl(fd, libc::F_GETFL);
        libc::fcntl(fd, libc::F_SETFL, flags | libc::O_NONBLOCK)
    };
    if r < 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}

/// Waits until `fd` is ready for `events` or `deadline` passes.
fn wait_ready(fd: &impl AsRawFd, events: i16, deadline: Instant) -> Result<(), Stop> {
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(Stop::Late);
        }
        let mut p = libc::pollfd {
            fd: fd.as_raw_fd(),
            events,
            revents: 0,
        };
        let ms = left.as_millis().clamp(1, i32::MAX as u128) as i32;
        // SAFETY: one valid pollfd.
        let r = unsafe { libc::poll(&mut p, 1, ms) };
        if r < 0 {
            let e = std::io::Error::last_os_error();
            if e.kind() == std::io::ErrorKind::Interrupted {
                continue;
            }
            return Err(Stop::Io(e));
        }
        if r > 0 {
            return Ok(());
        }
    }
}

fn read_exact_by(from: &mut File, buf: &mut [u8], deadline: Instant) -> Result<(), Stop> {
    let mut at = 0;
    while at < buf.len() {
        match from.read(&mut buf[at..]) {
            Ok(0) => return Err(Stop::Closed),
            Ok(n) => at += n,
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                wait_ready(from, libc::POLLIN, deadline)?
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(Stop::Io(e)),
        }
    }
    Ok(())
}

fn write_all_by(to: &mut File, mut bytes: &[u8], deadline: Instant) -> Result<(), Stop> {
    while !bytes.is_empty() {
        match to.write(bytes) {
            Ok(0) => return Err(Stop::Closed),
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                wait_ready(to, libc::POLLOUT, deadline)?
            }
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Err(Stop::Closed),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(Stop::Io(e)),
        }
    }
    Ok(())
}

/// Reads a frame of at most `max` bytes by `deadline`.
fn read_frame_by(from: &mut File, max: u64, deadline: Instant) -> Result<(u32, Vec<u8>), Stop> {
    let mut head = [0u8; 12];
    read_exact_by(from, &mut head, deadline)?;
    let (kind, len) = wire::header(&head);
    if len > max {
        return Err(Stop::Io(std::io::Error::other(format!(
            "it answered with {len} bytes, more than the {max} the call allows"
        ))));
    }
    let mut bytes = vec![0u8; len as usize];
    read_exact_by(from, &mut bytes, deadline)?;
    Ok((kind, bytes))
}

/// A signal's name and what it usually means.
fn signal_name(sig: i32) -> String {
    let (name, meaning) = match sig {
        libc::SIGSEGV => ("SIGSEGV", "a segmentation fault: memory it may not touch"),
        libc::SIGBUS => ("SIGBUS", "a bus error: memory that is not there"),
        libc::SIGABRT => ("SIGABRT", "it aborted"),
        libc::SIGILL => ("SIGILL", "an illegal instruction"),
        libc::SIGFPE => ("SIGFPE", "an arithmetic fault"),
        libc::SIGKILL => ("SIGKILL", "killed"),
        libc::SIGTERM => ("SIGTERM", "terminated"),
        libc::SIGXCPU => ("SIGXCPU", "past its CPU time"),
        _ => ("a signal", "ended by a signal"),
    };
    format!("signal {sig}, {name}: {meaning}")
}

impl State {
    /// The child's end, once its pipe closed or it broke the protocol:
    /// how it ended and what it last wrote. Waits a little for it to end,
    /// then kills it.
    fn ended(&mut self, during: &str, late: Option<Duration>) -> String {
        if let Some(g) = &self.gone {
            return g.clone();
        }
        let how = if let Some(limit) = late {
            let _ = self.child.kill();
            let _ = self.child.wait();
            format!(
                "did not answer within {} s during {during}: its process was stopped (a plugin call that loops?); allow more with --plugin-seconds",
                limit.as_secs_f64()
            )
        } else {
            let until = Instant::now() + Duration::from_secs(2);
            let status = loop {
                match self.child.try_wait() {
                    Ok(Some(s)) => break Some(s),
                    Ok(None) if Instant::now() < until => {
                        std::thread::sleep(Duration::from_millis(5))
                    }
                    _ => {
                        let _ = self.child.kill();
                        break self.child.wait().ok();
                    }
                }
            };
            use std::os::unix::process::ExitStatusExt;
            match status {
                Some(s) if s.signal().is_some() => format!(
                    "crashed during {during} ({})",
                    signal_name(s.signal().unwrap_or(0))
                ),
                Some(s) if during == LOADING => format!(
                    "ended its process during {during} (exit status {}{})",
                    s.code().unwrap_or(-1),
                    if self.said().contains("ld.so") {
                        ": the system's loader gave up on the library, which is damaged"
                    } else {
                        ""
                    }
                ),
                Some(s) => format!(
                    "ended its process during {during} (exit status {}): a plugin must return from its calls, never exit",
                    s.code().unwrap_or(-1)
                ),
                None => format!("stopped answering during {during}"),
            }
        };
        let said = self.said();
        let message = if said.is_empty() {
            how
        } else {
            format!("{how}; it wrote \"{}\"", crate::files::excerpt(&said))
        };
        self.gone = Some(message.clone());
        message
    }

    /// The last line the child wrote to its error stream (waiting a moment
    /// for the reader to catch up).
    fn said(&self) -> String {
        let until = Instant::now() + Duration::from_millis(500);
        loop {
            let done = self.tail.lock().map(|t| t.done).unwrap_or(true);
            if done || Instant::now() > until {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        let bytes = self
            .tail
            .lock()
            .map(|t| t.bytes.clone())
            .unwrap_or_default();
        let text = String::from_utf8_lossy(&bytes);
        text.lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("")
            .trim()
            .to_owned()
    }
}

/// Keeps the last [`TAIL_BYTES`] of `stream` in `tail`.
fn keep_tail(mut stream: impl Read, tail: Arc<Mutex<Tail>>) {
    let mut buf = [0u8; 4096];
    loop {
        match stream.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => {
                if let Ok(mut t) = tail.lock() {
                    t.bytes.extend_from_slice(&buf[..n]);
                    let extra = t.bytes.len().saturating_sub(TAIL_BYTES);
                    t.bytes.drain(..extra);
                }
            }
        }
    }
    if let Ok(mut t) = tail.lock() {
        t.done = true;
    }
}

impl Remote {
    /// Starts a child process serving `lib` (entry `symbol`; `shown` names
    /// it in messages) and reads its table's header.
    pub(super) fn start(
        lib: &Path,
        symbol: &str,
        shown: &str,
    ) -> Result<(Self, TableHeader), StartError> {
        let (program, bounds) = settings().map_err(StartError::Process)?;
        let mut child = Command::new(&program)
            .arg("plugin-server")
            .arg(lib)
            .arg(symbol)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                StartError::Process(format!(
                    "the program that loads plugins ({}) cannot be started: {e}",
                    crate::files::shown_path(&program)
                ))
            })?;
        let take = |child: &mut Child| -> Option<(File, File, std::process::ChildStderr)> {
            let to = File::from(OwnedFd::from(child.stdin.take()?));
            let from = File::from(OwnedFd::from(child.stdout.take()?));
            Some((to, from, child.stderr.take()?))
        };
        let Some((to, from, err)) = take(&mut child) else {
            let _ = child.kill();
            let _ = child.wait();
            return Err(StartError::Process("its pipes could not be opened".into()));
        };
        let tail = Arc::new(Mutex::new(Tail::default()));
        {
            let tail = tail.clone();
            std::thread::spawn(move || keep_tail(err, tail));
        }
        let mut state = State {
            child,
            to,
            from,
            tail,
            gone: None,
        };
        if let Err(e) = non_blocking(&state.to).and_then(|_| non_blocking(&state.from)) {
            let _ = state.child.kill();
            let _ = state.child.wait();
            return Err(StartError::Process(e.to_string()));
        }
        let deadline = Instant::now() + bounds.load;
        let mut hello = [0u8; 8];
        let stop = |state: &mut State, s: Stop, during: &str| match s {
            Stop::Late => state.ended(during, Some(bounds.load)),
            Stop::Closed => state.ended(during, None),
            Stop::Io(e) => {
                let _ = state.child.kill();
                let m = state.ended(during, None);
                format!("{m} ({e})")
            }
        };
        if let Err(s) = read_exact_by(&mut state.from, &mut hello, deadline) {
            let m = stop(&mut state, s, "its start");
            return Err(StartError::Process(format!(
                "the program that loads plugins ({}) {m}",
                crate::files::shown_path(&program)
            )));
        }
        if &hello != wire::HELLO {
            let _ = state.child.kill();
            let _ = state.child.wait();
            return Err(StartError::Process(format!(
                "{} does not serve plugins (it is not this pilgrim)",
                crate::files::shown_path(&program)
            )));
        }
        let during = LOADING;
        let (kind, bytes) = read_frame_by(&mut state.from, wire::MAX_MESSAGE as u64, deadline)
            .map_err(|s| StartError::Process(stop(&mut state, s, during)))?;
        let reap = |state: &mut State| {
            let _ = state.child.kill();
            let _ = state.child.wait();
        };
        match kind {
            wire::LOADED => match TableHeader::decode(&bytes) {
                Some(h) => Ok((
                    Self {
                        library: shown.to_owned(),
                        bounds,
                        state: Mutex::new(state),
                    },
                    h,
                )),
                None => {
                    reap(&mut state);
                    Err(StartError::Process("its table could not be read".into()))
                }
            },
            wire::OPEN_FAILED => {
                reap(&mut state);
                Err(StartError::Open(
                    String::from_utf8_lossy(&bytes).into_owned(),
                ))
            }
            wire::NO_ENTRY => {
                reap(&mut state);
                Err(StartError::NoEntry)
            }
            wire::NULL_TABLE => {
                reap(&mut state);
                Err(StartError::NullTable)
            }
            _ => {
                reap(&mut state);
                Err(StartError::Process(
                    "it broke the protocol while loading".into(),
                ))
            }
        }
    }

    /// Sends a request and reads its answer: the answer's bytes (at most
    /// `max`), or the plugin's failure, or what became of its process.
    fn call(
        &self,
        kind: u32,
        request: &[u8],
        max: u64,
        during: &str,
    ) -> Result<Vec<u8>, CallError> {
        let mut state = self
            .state
            .lock()
            .map_err(|_| CallError::whole("the plugin's process is lost"))?;
        let lib = &self.library;
        if let Some(g) = &state.gone {
            return Err(CallError::whole(format!("the plugin {lib} {g}")));
        }
        let (limit, deadline) = crate::budget::bounded(self.bounds.call);
        let mut frame = Vec::with_capacity(12 + request.len());
        let _ = wire::write_frame(&mut frame, kind, &[request]);
        let result = write_all_by(&mut state.to, &frame, deadline).and_then(|_| {
            read_frame_by(
                &mut state.from,
                max.max(wire::MAX_MESSAGE as u64 + 8),
                deadline,
            )
        });
        match result {
            Ok((status, bytes)) if status == pilgrim_plugin_abi::STATUS_OK as u32 => {
                if bytes.len() as u64 > max {
                    let m = format!(
                        "answered {during} with {} bytes, more than the {max} it may",
                        bytes.len()
                    );
                    return Err(CallError::whole(format!("the plugin {lib} {m}")));
                }
                Ok(bytes)
            }
            Ok((_, bytes)) => {
                let (row, message) = wire::parse_failure(&bytes);
                Err(CallError {
                    row: usize::try_from(row).ok().filter(|&r| r != pilgrim_plugin_abi::NO_ROW),
                    message: crate::files::excerpt(&message),
                })
            }
            Err(Stop::Late) if limit.is_some() => Err(CallError::whole(format!(
                "the run ran past its time limit of {} s during {during} of the plugin {}: the plugin's process was stopped",
                limit.map_or(0.0, |s| s),
                self.library
            ))),
            Err(Stop::Late) => Err(CallError::whole(format!(
                "the plugin {lib} {}",
                state.ended(during, Some(self.bounds.call))
            ))),
            Err(Stop::Closed) => Err(CallError::whole(format!(
                "the plugin {lib} {}",
                state.ended(during, None)
            ))),
            Err(Stop::Io(e)) => {
                let _ = state.child.kill();
                let m = state.ended(during, None);
                Err(CallError::whole(format!("the plugin {lib} {m} ({e})")))
            }
        }
    }

    /// A batch call, in pieces of at most [`CHUNK_ROWS`] rows.
    fn batch(
        &self,
        shape: &Batch<'_>,
        rows: &[f64],
        tool: &[f64; 6],
        width: usize,
        out: &mut [f64],
    ) -> Result<(), CallError> {
        let &Batch {
            kind,
            row_len,
            out_len,
            during,
        } = shape;
        let count = rows.len().checked_div(row_len).unwrap_or(0);
        let mut done = 0;
        while done < count {
            let n = (count - done).min(CHUNK_ROWS);
            let request =
                wire::batch_request(n, width, tool, &rows[done * row_len..(done + n) * row_len]);
            let bytes = self
                .call(kind, &request, (n * out_len * 8) as u64, during)
                .map_err(|mut e| {
                    e.row = e.row.filter(|&r| r < n).map(|r| r + done);
                    e
                })?;
            let values = wire::bytes_to_floats(&bytes)
                .filter(|v| v.len() == n * out_len)
                .ok_or_else(|| {
                    CallError::whole(format!(
                        "the plugin {} answered {during} with {} bytes, not {} values",
                        self.library,
                        bytes.len(),
                        n * out_len
                    ))
                })?;
            out[done * out_len..(done + n) * out_len].copy_from_slice(&values);
            done += n;
        }
        Ok(())
    }
}

/// What one kind of batch call sends and receives per row.
struct Batch<'a> {
    /// The request's kind (`wire::INVERSE`, `wire::FORWARD`).
    kind: u32,
    /// Values sent per row.
    row_len: usize,
    /// Values answered per row.
    out_len: usize,
    /// What the call is doing, for messages.
    during: &'a str,
}

impl Calls for Remote {
    fn describe(&self) -> Result<String, CallError> {
        let bytes = self.call(wire::DESCRIBE, &[], wire::MAX_FRAME, "describe")?;
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }

    fn inverse(
        &self,
        poses: &[f64],
        tool: &[f64; 6],
        width: usize,
        out: &mut [f64],
    ) -> Result<(), CallError> {
        let during = format!("inverse kinematics of {} poses", poses.len() / 6);
        let shape = Batch {
            kind: wire::INVERSE,
            row_len: 6,
            out_len: width,
            during: &during,
        };
        self.batch(&shape, poses, tool, width, out)
    }

    fn forward(
        &self,
        axes: &[f64],
        tool: &[f64; 6],
        width: usize,
        out: &mut [f64],
    ) -> Result<(), CallError> {
        let during = format!(
            "forward kinematics of {} rows",
            axes.len().checked_div(width).unwrap_or(0)
        );
        let shape = Batch {
            kind: wire::FORWARD,
            row_len: width,
            out_len: 6,
            during: &during,
        };
        self.batch(&shape, axes, tool, width, out)
    }

    fn post(&self, request: &[u8]) -> Result<String, CallError> {
        let bytes = self.call(wire::POST, request, wire::MAX_FRAME, "post")?;
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }
}

impl Drop for Remote {
    fn drop(&mut self) {
        if let Ok(state) = self.state.get_mut() {
            if state.gone.is_none() {
                let _ = state.child.kill();
            }
            let _ = state.child.wait();
        }
    }
}
