//! Everything `trocar` prints: matrices as aligned text or JSON, and errors.

use trocar_api::{Error, Evaluation};

/// An error of the command line: printed to stderr as `error: …`, exit code 1.
pub(crate) type CliError = Error;

/// Writes `text` to stdout. A reader that has gone away (`trocar generate … | head`) is not an
/// error: the rest of the output is unwanted, and the command ends normally instead of panicking
/// on the broken pipe. Any other failure to write is an error.
pub(crate) fn write_stdout(text: &str) -> Result<(), CliError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Error::Output(format!("cannot write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

/// What an output file holds, for the checks made before any work: `trocar simulate --plot`
/// and `--snapshot` must name a `.svg` or `.png` file, `--animate` a `.gif`; a CSV or a
/// generated module may have any name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum OutputKind {
    /// A figure (`--plot`, `--snapshot`): SVG or PNG, by the extension.
    Figure,
    /// An animation (`--animate`): GIF.
    Animation,
    /// Anything else (`--csv`, `generate -o`).
    Data,
}

/// Writes `text` to stderr: notes, summaries and errors. A failure to write stderr (its reader
/// gone away, as in `trocar simulate four-bar 2>&1 | head -1`; a full device) has nowhere to be
/// reported, so it is ignored and the command ends quietly with its normal status, where
/// `eprintln!` panicked (exit code 101).
pub(crate) fn write_stderr(text: &str) {
    use std::io::Write;
    let mut err = std::io::stderr().lock();
    let _ = err.write_all(text.as_bytes()).and_then(|()| err.flush());
}

/// The longest file name, in bytes, that an output may have (`NAME_MAX` of Linux and most file
/// systems). Longer names are refused before any work.
pub(crate) const MAX_FILE_NAME: usize = 255;

/// How many symbolic links are followed to find the file an output replaces (Linux's limit).
const MAX_LINKS: usize = 40;

/// The output files of one command, checked before the command does any work and written
/// atomically after it has succeeded: all or none.
///
/// [`Outputs::check`] checks every path (a file name of at most [`MAX_FILE_NAME`] bytes in a
/// directory that exists, the extension of figures and animations, no two outputs the same file,
/// no output that is a file the command reads) and then creates, in the directory of each file
/// to be replaced, a temporary file: exclusively (never through an existing file or link), under
/// an unpredictable name that keeps the requested extension (`.fig.Xa9Tq2.svg`; a figure's format
/// follows it), with the permission mode of the file it replaces, if any. Creating it is also the
/// check that the directory is writable. The command writes each output into its temporary; once
/// all are written, [`Outputs::commit`] renames them over the requested files, and if one of the
/// renames fails, puts back the files already replaced. Temporaries are removed on every error
/// path (when the `Outputs` is dropped) and on SIGINT, SIGTERM and SIGHUP, after which the process
/// exits with 128 + the signal's number.
///
/// A symbolic link is followed, also when it dangles: the file it points to is replaced (or
/// created) and the link kept. A path that exists as something other than a regular file — a
/// device such as `/dev/null`, a FIFO, a socket — is written in place (renaming over it would
/// replace the device node with a plain file).
#[derive(Debug, Default)]
pub(crate) struct Outputs {
    files: Vec<OutputFile>,
}

/// One output of a command.
#[derive(Debug)]
struct OutputFile {
    /// The option that named it (`--csv`, `-o` …), for errors.
    option: &'static str,
    /// The path as the user gave it.
    requested: PathBuf,
    /// The file that [`Outputs::commit`] replaces or creates: the requested path with its
    /// symbolic links followed.
    target: PathBuf,
    /// Where the output is written until the commit; `None` when it is written in place.
    temp: Option<PathBuf>,
}

use std::path::{Path, PathBuf};

/// The temporary files of this process, removed by the signal handler ([`cleanup`]).
mod cleanup {
    use std::path::PathBuf;
    use std::sync::{Mutex, MutexGuard, Once};

    static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    static HANDLER: Once = Once::new();

    /// The registered temporaries, locked: the signal handler waits while a command creates,
    /// renames or removes them.
    pub(super) fn lock() -> MutexGuard<'static, Vec<PathBuf>> {
        TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Installs, once, the handler of SIGINT, SIGTERM and SIGHUP: a thread that removes the
    /// registered temporaries and exits with 128 + the signal's number. Without it the default
    /// action of those signals would end the process and leave its temporaries behind.
    pub(super) fn install() {
        HANDLER.call_once(|| {
            use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
            let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
            else {
                return;
            };
            std::thread::spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    let mut temps = lock();
                    for temp in temps.drain(..) {
                        let _ = std::fs::remove_file(temp);
                    }
                    std::process::exit(128 + signal);
                }
            });
        });
    }
}

/// Whether `a` and `b` are the same existing file (the same device and inode, links followed).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
    }
}

/// `path` with its symbolic links followed (also a dangling one: the path it points to), or an
/// error when there are more than [`MAX_LINKS`] of them (a loop).
fn resolve(path: &Path) -> Result<PathBuf, String> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&p).map_err(|e| e.to_string())?;
                p = if link.is_absolute() {
                    link
                } else {
                    directory(&p).join(link)
                };
            }
            _ => return Ok(p),
        }
    }
    Err("too many levels of symbolic links".into())
}

/// The byte length of a file name.
fn name_len(name: &std::ffi::OsStr) -> usize {
    name.as_encoded_bytes().len()
}

impl Outputs {
    /// Checks the outputs up front and creates their temporaries (see [`Outputs`]): every path
    /// names a file of at most [`MAX_FILE_NAME`] bytes in a writable directory that exists,
    /// figures end in `.svg` or `.png`, animations in `.gif`, no two outputs are the same file,
    /// and no output is one of `reads`, the files the command reads. Errors name the option and
    /// the path.
    pub(crate) fn check(
        requested: &[(&'static str, Option<&Path>, OutputKind)],
        reads: &[PathBuf],
    ) -> Result<Outputs, CliError> {
        // What each output is, checked before anything is created: (option, path, target, kind,
        // replaced file's permissions or None for a new file, written in place).
        let mut planned = Vec::new();
        let mut seen: Vec<(&'static str, &Path, (PathBuf, std::ffi::OsString))> = Vec::new();
        for &(option, path, kind) in requested {
            let Some(path) = path else { continue };
            let shown = path.display();
            let err = |m: String| Error::Input(format!("{option} {shown}: {m}"));
            let Some(name) = path.file_name() else {
                return Err(err("not a file name".into()));
            };
            if name_len(name) > MAX_FILE_NAME {
                return Err(err(format!(
                    "the file name is {} bytes long; at most {MAX_FILE_NAME} are allowed",
                    name_len(name)
                )));
            }
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
            if kind == OutputKind::Figure && trocar_api::ImageFormat::of(path).is_none() {
                return Err(err(
                    "a figure is written as SVG or PNG; name the file `….svg` or `….png`".into(),
                ));
            }
            if kind == OutputKind::Animation && !ext.eq_ignore_ascii_case("gif") {
                return Err(err(
                    "an animation is written as GIF; name the file `….gif`".into()
                ));
            }
            let dir = directory(path);
            if !dir.is_dir() {
                return Err(err(format!(
                    "the directory {} does not exist",
                    dir.display()
                )));
            }
            if path.is_dir() {
                return Err(err("is a directory".into()));
            }
            let target = resolve(path).map_err(err)?;
            let target_dir = directory(&target);
            if target != path {
                if !target_dir.is_dir() {
                    return Err(err(format!(
                        "a symbolic link to {}, in a directory that does not exist",
                        target.display()
                    )));
                }
                if target
                    .file_name()
                    .is_none_or(|n| name_len(n) > MAX_FILE_NAME)
                {
                    return Err(err(format!(
                        "a symbolic link to {}, which is not a file name this output can have",
                        target.display()
                    )));
                }
            }
            let (mode, in_place) = match std::fs::metadata(&target) {
                Ok(m) if m.is_dir() => return Err(err("is a directory".into())),
                Ok(m) if !m.is_file() => (None, true),
                Ok(m) => (Some(m.permissions()), false),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => (None, false),
                Err(e) => return Err(err(e.to_string())),
            };
            if let Some(read) = reads.iter().find(|r| same_file(&target, r)) {
                return Err(err(format!(
                    "is {}, which this command reads; write the output to another file",
                    read.display()
                )));
            }
            // The same file under two names: the directories resolved and the names.
            let key = (
                target_dir.canonicalize().unwrap_or(target_dir),
                target.file_name().unwrap_or(name).to_owned(),
            );
            if let Some((other, other_path, _)) = seen.iter().find(|(_, _, k)| *k == key) {
                return Err(err(format!(
                    "{other} {} is the same file; two outputs cannot be one file",
                    other_path.display()
                )));
            }
            seen.push((option, path, key));
            planned.push((option, path, target, mode, in_place));
        }
        let mut out = Outputs::default();
        if planned.iter().any(|p| !p.4) {
            cleanup::install();
        }
        for (option, path, target, mode, in_place) in planned {
            let temp = if in_place {
                None
            } else {
                let temp = create_temporary(path, &target, mode).map_err(|e| {
                    // The OS's error alone: tempfile's also names the random temporary.
                    let e = e.to_string();
                    let e = e.split(" at path ").next().unwrap_or_default();
                    Error::Input(format!(
                        "{option} {}: cannot write in the directory {}: {e}",
                        path.display(),
                        directory(&target).display()
                    ))
                })?;
                Some(temp)
            };
            out.files.push(OutputFile {
                option,
                requested: path.to_path_buf(),
                target,
                temp,
            });
        }
        Ok(out)
    }

    /// Where to write the output requested as `path` until [`Outputs::commit`].
    pub(crate) fn temporary<'a>(&'a self, path: &'a Path) -> &'a Path {
        self.files
            .iter()
            .find(|f| f.requested == path)
            .map_or(path, |f| f.temp.as_deref().unwrap_or(&f.target))
    }

    /// `e` with every temporary file name replaced by the name the user gave.
    pub(crate) fn explain(&self, e: String) -> CliError {
        let mut text = e;
        for f in &self.files {
            let written = f.temp.as_deref().unwrap_or(&f.target);
            text = text.replace(
                &written.display().to_string(),
                &f.requested.display().to_string(),
            );
        }
        Error::Output(text)
    }

    /// Renames every temporary file over its requested file, all or none: when a rename fails,
    /// the files already replaced are put back (the replaced ones from a hard link kept until
    /// the end, the new ones removed), and the error says whether that succeeded.
    pub(crate) fn commit(mut self) -> Result<(), CliError> {
        let mut registered = cleanup::lock();
        let files = std::mem::take(&mut self.files);
        // The outputs renamed so far, with the second name of the file each replaced.
        let mut done: Vec<(&OutputFile, Option<PathBuf>)> = Vec::new();
        let mut failure = None;
        for f in &files {
            let Some(temp) = &f.temp else { continue };
            let backup = std::fs::symlink_metadata(&f.target)
                .is_ok_and(|m| m.is_file())
                .then(|| {
                    let mut b = temp.clone().into_os_string();
                    b.push(".old");
                    PathBuf::from(b)
                })
                .filter(|b| std::fs::hard_link(&f.target, b).is_ok());
            match std::fs::rename(temp, &f.target) {
                Ok(()) => done.push((f, backup)),
                Err(e) => {
                    if let Some(b) = backup {
                        let _ = std::fs::remove_file(b);
                    }
                    failure = Some((f, e));
                    break;
                }
            }
        }
        let result = match failure {
            None => Ok(()),
            Some((f, e)) => {
                let mut lost = Vec::new();
                for (g, backup) in done.iter().rev() {
                    let restored = match backup {
                        Some(b) => std::fs::rename(b, &g.target),
                        None => std::fs::remove_file(&g.target),
                    };
                    if restored.is_err() {
                        lost.push(format!("{} {}", g.option, g.requested.display()));
                    }
                }
                done.clear();
                let state = if lost.is_empty() {
                    "no output was written".to_string()
                } else {
                    format!(
                        "the outputs already written could not all be put back: {} replaced",
                        lost.join(", ")
                    )
                };
                Err(Error::Output(format!(
                    "{} {}: cannot replace the file: {e}; {state}",
                    f.option,
                    f.requested.display()
                )))
            }
        };
        for (_, backup) in done {
            if let Some(b) = backup {
                let _ = std::fs::remove_file(b);
            }
        }
        for temp in files.iter().filter_map(|f| f.temp.as_ref()) {
            let _ = std::fs::remove_file(temp);
            registered.retain(|r| r != temp);
        }
        result
    }
}

/// Creates the temporary of the output `requested` that replaces `target`, in `target`'s
/// directory: exclusively, under an unpredictable name `.<stem>.<random>.<extension>` (the stem
/// shortened to keep the name within [`MAX_FILE_NAME`] bytes; the extension of the requested
/// name, which a figure's format follows), with `mode`, the permissions of the file it
/// replaces, or those of a new file. Registers it for removal on a signal.
fn create_temporary(
    requested: &Path,
    target: &Path,
    mode: Option<std::fs::Permissions>,
) -> std::io::Result<PathBuf> {
    let suffix = requested
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .filter(|s| s.len() <= 16)
        .unwrap_or_default();
    let mut stem: String = target
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    // `.` + stem + `.` + 6 random characters + suffix.
    let budget = MAX_FILE_NAME - 8 - suffix.len();
    while stem.len() > budget {
        stem.pop();
    }
    let prefix = format!(".{stem}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(&suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut registered = cleanup::lock();
    let file = builder.tempfile_in(directory(target))?;
    let path = file.into_temp_path();
    if let Some(mode) = mode {
        std::fs::set_permissions(&path, mode)?;
    }
    let path = path.keep().map_err(|e| e.error)?;
    registered.push(path.clone());
    Ok(path)
}

/// The directory a file `path` goes into (`.` for a bare file name).
fn directory(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

impl Drop for Outputs {
    /// Removes the temporary files of a command that failed.
    fn drop(&mut self) {
        let mut registered = cleanup::lock();
        for temp in self.files.iter().filter_map(|f| f.temp.as_ref()) {
            let _ = std::fs::remove_file(temp);
            registered.retain(|r| r != temp);
        }
    }
}

/// One entry of a text matrix: nine decimals, or scientific notation with ten significant digits
/// from `1e9` on (a value such as `1.5e298` would otherwise print as 300 digits) and for a
/// nonzero value below `1e-4` (which nine decimals would print as `0.000000000` or with few
/// digits).
fn cell(v: f64) -> String {
    if v.abs() >= 1e9 || (v != 0.0 && v.abs() < 1e-4) {
        format!("{v:.9e}")
    } else {
        format!("{v:.9}")
    }
}

/// Prints an error to stderr and returns the exit code of a failed command. An argument the
/// library names ([`Error::Argument`]) is printed as the flag that gives it.
pub(crate) fn print_error(e: &CliError) -> i32 {
    let text = match e {
        Error::Argument { argument, problem } => format!("{}: {problem}", flag(argument)),
        e => e.to_string(),
    };
    write_stderr(&format!("error: {text}\n"));
    1
}

/// The flag of the library's argument `argument`: `--` and its name in kebab case (`q0` →
/// `--q0`, `max_joint_speed` → `--max-joint-speed`), but `params` → `--param` (one a flag).
pub(crate) fn flag(argument: &str) -> String {
    match argument {
        "params" => "--param".to_string(),
        a => format!("--{}", a.replace('_', "-")),
    }
}

/// The JSON form `{"rows": R, "cols": C, "data": [[row], ...]}` (keys in this order).
pub(crate) fn to_json(m: &Evaluation) -> String {
    let data =
        serde_json::to_string(&m.to_rows()).expect("finite or null numbers always serialise");
    format!(
        r#"{{"rows": {}, "cols": {}, "data": {data}}}"#,
        m.rows, m.cols
    )
}

/// Aligned text, one row a line.
pub(crate) fn to_text(m: &Evaluation) -> String {
    let cells: Vec<Vec<String>> = m
        .to_rows()
        .iter()
        .map(|r| r.iter().map(|v| cell(*v)).collect())
        .collect();
    let width = cells.iter().flatten().map(String::len).max().unwrap_or(0);
    cells
        .iter()
        .map(|r| {
            r.iter()
                .map(|c| format!("{c:>width$}"))
                .collect::<Vec<_>>()
                .join("  ")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Aligned text with a header of column labels and each row's label in front (labels of the
/// wrong count are ignored: the plain [`to_text`] is returned). Whitespace inside a label becomes
/// `_`, so each line is still one label and numbers.
pub(crate) fn to_labelled_text(
    m: &Evaluation,
    row_labels: &[String],
    col_labels: &[String],
) -> String {
    if row_labels.len() != m.rows || col_labels.len() != m.cols || m.cols == 0 {
        return to_text(m);
    }
    let clean = |l: &String| l.split_whitespace().collect::<Vec<_>>().join("_");
    let rows: Vec<String> = row_labels.iter().map(clean).collect();
    let cols: Vec<String> = col_labels.iter().map(clean).collect();
    let cells: Vec<Vec<String>> = m
        .to_rows()
        .iter()
        .map(|r| r.iter().map(|v| cell(*v)).collect())
        .collect();
    let width = cells
        .iter()
        .flatten()
        .chain(&cols)
        .map(|c| c.chars().count())
        .max()
        .unwrap_or(0);
    let first = rows.iter().map(|r| r.chars().count()).max().unwrap_or(0);
    let mut lines = vec![format!(
        "{:first$}  {}",
        "",
        cols.iter()
            .map(|c| format!("{c:>width$}"))
            .collect::<Vec<_>>()
            .join("  ")
    )];
    for (label, r) in rows.iter().zip(&cells) {
        lines.push(format!(
            "{label:<first$}  {}",
            r.iter()
                .map(|c| format!("{c:>width$}"))
                .collect::<Vec<_>>()
                .join("  ")
        ));
    }
    lines.join("\n")
}

/// Prints the matrix to stdout, as JSON or aligned text ([`write_stdout`]); the text has row and
/// column labels when `labels` are given.
pub(crate) fn print_matrix(
    m: &Evaluation,
    json: bool,
    labels: Option<(Vec<String>, Vec<String>)>,
) -> Result<(), CliError> {
    let text = match (json, labels) {
        (true, _) => to_json(m),
        (false, Some((rows, cols))) => to_labelled_text(m, &rows, &cols),
        (false, None) => to_text(m),
    };
    write_stdout(&format!("{text}\n"))
}

#[cfg(test)]
mod tests {
    use super::cell;

    /// Issue 27, item 12: small values printed as `0.000000000`.
    #[test]
    fn small_values_keep_their_digits() {
        assert_eq!(cell(1.234e-12), "1.234000000e-12");
        assert_eq!(cell(-5e-5), "-5.000000000e-5");
        assert_eq!(cell(0.0), "0.000000000");
        assert_eq!(cell(0.25), "0.250000000");
        assert_eq!(cell(1.5e298), "1.500000000e298");
    }
}
