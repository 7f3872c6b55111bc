//! `runs.jsonl`: one [`RunRecord`] per line, appended and flushed as each run finishes.
//!
//! A kill can leave at most one torn line: the last one, without its newline. Reading ignores
//! it (that run is redone) and [`RunLog::open_for_append`] truncates it away before appending,
//! so a resumed file never holds half a record. A last line that lacks only its newline (a
//! kill just before it, or a file saved by an editor) is a whole record: it is read, and
//! appending first ends its line. A complete line that does not parse is not a
//! kill's doing: it is reported as corruption rather than skipped.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use super::ExperimentError;
use super::record::RunRecord;

/// File name of the run log in a results directory.
pub const RUNS_FILE: &str = "runs.jsonl";

/// The records of a run log and what was found at its end.
#[derive(Debug, Clone, PartialEq)]
pub struct Loaded {
    /// Complete, parsed records, in file order.
    pub records: Vec<RunRecord>,
    /// The lines the records were parsed from (without newline), to copy them exactly: JSON
    /// float parsing may be off by an ulp, so re-serializing a parsed record could change it.
    pub lines: Vec<String>,
    /// The 1-based line number of each record in the file, for messages.
    pub line_numbers: Vec<usize>,
    /// Length in bytes of the complete lines (where appending resumes), a last record
    /// without its newline included.
    pub valid_len: u64,
    /// Bytes of a torn last line (no newline, not a whole record), ignored; 0 if none.
    pub torn_bytes: u64,
}

/// Refuses `path` when it exists and is not a regular file (a directory, a FIFO, which a read
/// would wait on forever, or a device such as `/dev/zero`, read until memory runs out),
/// after following links.
pub fn refuse_irregular(path: &Path) -> Result<(), ExperimentError> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => {
            let kind = if meta.is_dir() {
                "a directory"
            } else {
                "a FIFO, socket or device"
            };
            Err(ExperimentError::Corrupt {
                path: path.to_path_buf(),
                message: format!("is {kind}, not a regular file"),
            })
        }
        _ => Ok(()),
    }
}

/// Reads a run log. A missing file is an empty log; one that is not a regular file is
/// refused ([`refuse_irregular`]).
pub fn read(path: &Path) -> Result<Loaded, ExperimentError> {
    refuse_irregular(path)?;
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(ExperimentError::io(path, e)),
    };
    let mut valid_len = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let mut torn_bytes = bytes.len() - valid_len;
    let tail = &bytes[valid_len..];
    if tail.iter().all(u8::is_ascii_whitespace) {
        // Trailing blanks: nothing torn, and appending truncates them.
        torn_bytes = 0;
    } else if serde_json::from_slice::<RunRecord>(tail).is_ok() {
        // A whole record without its newline: read like the others.
        valid_len = bytes.len();
        torn_bytes = 0;
    }
    let mut records = Vec::new();
    let mut lines = Vec::new();
    let mut line_numbers = Vec::new();
    for (n, line) in bytes[..valid_len].split(|&b| b == b'\n').enumerate() {
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let rec: RunRecord =
            serde_json::from_slice(line).map_err(|e| ExperimentError::Corrupt {
                path: path.to_path_buf(),
                message: match field_before(line, e.column()) {
                    // A missing or repeated field is named by serde itself, at the end of
                    // its object, where the last field before is another.
                    Some(field) if e.is_data() && !names_its_field(&e) => {
                        format!("line {}: {field}: {}", n + 1, at_column(&e))
                    }
                    _ => format!("line {}: {}", n + 1, at_column(&e)),
                },
            })?;
        records.push(rec);
        lines.push(String::from_utf8_lossy(line).into_owned());
        line_numbers.push(n + 1);
    }
    Ok(Loaded {
        records,
        lines,
        line_numbers,
        valid_len: valid_len as u64,
        torn_bytes: torn_bytes as u64,
    })
}

/// serde_json's message with its position as a column of the record's line: it counts
/// lines within the one record it was given ("... at line 1 column 19"), which read beside
/// the file's line number as another line.
fn at_column(e: &serde_json::Error) -> String {
    let text = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    match text.strip_suffix(&suffix) {
        Some(head) if e.line() == 1 => format!("{head} at column {}", e.column()),
        _ => text,
    }
}

/// Whether serde's message names the field itself ("missing field `window`", "duplicate field
/// `quads`", "unknown field ...").
fn names_its_field(e: &serde_json::Error) -> bool {
    let text = e.to_string();
    ["missing field `", "duplicate field `", "unknown field `"]
        .iter()
        .any(|p| text.starts_with(p))
}

/// The name of the field whose value ends at `column` (1-based, serde_json's position of a
/// data error) in a record's line: the last `"name":` before it. Serde names the value's
/// type, not its field.
fn field_before(line: &[u8], column: usize) -> Option<String> {
    let text = std::str::from_utf8(line).ok()?;
    let head = text.get(..column.min(text.len()))?;
    let colon = head.rfind("\":")?;
    let start = head[..colon].rfind('"')? + 1;
    let name = &head[start..colon];
    (!name.is_empty() && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_'))
        .then(|| format!("field {name}"))
}

/// An open run log that appends one flushed line per record.
#[derive(Debug)]
pub struct RunLog {
    path: PathBuf,
    file: File,
}

impl RunLog {
    /// Opens `path` for appending after its first `valid_len` bytes, truncating anything after
    /// them (a torn last line), and ends a last line that lacks its newline. Creates the file
    /// if needed.
    pub fn open_for_append(path: &Path, valid_len: u64) -> Result<RunLog, ExperimentError> {
        use std::io::{Read, Seek};
        let mut file = OpenOptions::new()
            .create(true)
            .truncate(false)
            .read(true)
            .write(true)
            .open(path)
            .map_err(|e| ExperimentError::io(path, e))?;
        let mut last = [b'\n'];
        if valid_len > 0 {
            file.seek(std::io::SeekFrom::Start(valid_len - 1))
                .and_then(|_| file.read_exact(&mut last))
                .map_err(|e| ExperimentError::io(path, e))?;
        }
        file.set_len(valid_len)
            .map_err(|e| ExperimentError::io(path, e))?;
        let mut log = RunLog {
            path: path.to_path_buf(),
            file,
        };
        log.file
            .seek(std::io::SeekFrom::Start(valid_len))
            .map_err(|e| ExperimentError::io(path, e))?;
        if last[0] != b'\n' {
            log.file
                .write_all(b"\n")
                .map_err(|e| ExperimentError::io(path, e))?;
        }
        Ok(log)
    }

    /// Creates (or empties) `path` for a fresh log.
    pub fn create(path: &Path) -> Result<RunLog, ExperimentError> {
        let file = File::create(path).map_err(|e| ExperimentError::io(path, e))?;
        Ok(RunLog {
            path: path.to_path_buf(),
            file,
        })
    }

    /// Appends one record as one line, in one write, and flushes it to the OS.
    pub fn append(&mut self, rec: &RunRecord) -> Result<(), ExperimentError> {
        self.append_line(&rec.to_json_line())
    }

    /// Appends a line already serialized (from another run log), newline added.
    pub fn append_line(&mut self, line: &str) -> Result<(), ExperimentError> {
        let mut line = line.to_string();
        line.push('\n');
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.flush())
            .map_err(|e| ExperimentError::io(&self.path, e))
    }

    /// Flushes the file to the disk (at the end of a sweep).
    pub fn sync(&mut self) -> Result<(), ExperimentError> {
        self.file
            .sync_data()
            .map_err(|e| ExperimentError::io(&self.path, e))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn record(run: u32) -> RunRecord {
        RunRecord {
            mesh: "m".into(),
            mesh_hash: "00".into(),
            triangles: 100,
            algo: "selective".into(),
            horizon: Some(2),
            budget: None,
            time_budget_s: None,
            seed: 42 + u64::from(run),
            run,
            quads: 48,
            triangles_left: 4,
            recombined_pct: 96.0,
            quality: 40.5,
            quality_pct: Some(97.25),
            time_s: 0.01,
            nodes_expanded: Some(300),
            trees: Some(48),
            decisions: 48,
            branching_factor: Some(1.9),
            worst_eta: Some(0.2),
            mean_eta: Some(0.84),
            quads_eta_below_0_1: Some(0),
            quads_eta_below_0_3: Some(1),
            min_eta: 0.0,
            allow_invalid: false,
            backend: "cpu-twin".into(),
            version: "0.1.0".into(),
            finish: None,
        }
    }

    /// A value of the wrong type is named by its field; a missing or repeated field by
    /// serde's own words, not by the field before the end of the object.
    #[test]
    fn errors_name_the_right_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(RUNS_FILE);
        let line = record(0).to_json_line();
        let message = |text: String| {
            std::fs::write(&path, text + "\n").unwrap();
            match read(&path) {
                Err(ExperimentError::Corrupt { message, .. }) => message,
                other => panic!("{other:?}"),
            }
        };
        let m = message(line.replace("\"quads\":48", "\"quads\":\"x\""));
        assert!(m.starts_with("line 1: field quads: invalid type"), "{m}");
        let dup = format!("{},\"quads\":3}}", &line[..line.len() - 1]);
        let m = message(dup);
        assert!(m.starts_with("line 1: duplicate field `quads`"), "{m}");
        let missing = line.replace("\"seed\":42,", "");
        let m = message(missing);
        assert!(m.starts_with("line 1: missing field `seed`"), "{m}");
    }

    #[test]
    fn append_then_read_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(RUNS_FILE);
        let mut log = RunLog::create(&path).unwrap();
        for r in 0..3 {
            log.append(&record(r)).unwrap();
        }
        let loaded = read(&path).unwrap();
        assert_eq!(loaded.records, (0..3).map(record).collect::<Vec<_>>());
        assert_eq!(loaded.torn_bytes, 0);
        assert_eq!(loaded.valid_len, std::fs::metadata(&path).unwrap().len());
    }

    #[test]
    fn torn_last_line_is_ignored_then_truncated() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(RUNS_FILE);
        let mut log = RunLog::create(&path).unwrap();
        log.append(&record(0)).unwrap();
        log.append(&record(1)).unwrap();
        drop(log);
        let full = std::fs::read(&path).unwrap();
        // Tear the second line in the middle.
        let first_len = full.iter().position(|&b| b == b'\n').unwrap() + 1;
        std::fs::write(&path, &full[..first_len + 20]).unwrap();
        let loaded = read(&path).unwrap();
        assert_eq!(loaded.records, vec![record(0)]);
        assert_eq!(loaded.valid_len, first_len as u64);
        assert_eq!(loaded.torn_bytes, 20);
        let mut log = RunLog::open_for_append(&path, loaded.valid_len).unwrap();
        log.append(&record(1)).unwrap();
        drop(log);
        assert_eq!(std::fs::read(&path).unwrap(), full);
        assert_eq!(read(&path).unwrap().records, vec![record(0), record(1)]);
    }

    /// A last record that lacks only its newline (a kill just before it, an editor's save)
    /// is read, and appending ends its line first; trailing blanks are not a torn line. Every
    /// proper prefix of a record is still torn.
    #[test]
    fn a_last_record_without_its_newline_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(RUNS_FILE);
        let mut full = String::new();
        for r in 0..3 {
            full.push_str(&record(r).to_json_line());
            full.push('\n');
        }
        for lines in 1..=2 {
            let text: String = full.split_inclusive('\n').take(lines).collect();
            let unterminated = text.trim_end_matches('\n');
            std::fs::write(&path, unterminated).unwrap();
            let loaded = read(&path).unwrap();
            assert_eq!(
                loaded.records,
                (0..lines as u32).map(record).collect::<Vec<_>>()
            );
            assert_eq!(loaded.line_numbers, (1..=lines).collect::<Vec<_>>());
            assert_eq!(
                (loaded.valid_len, loaded.torn_bytes),
                (unterminated.len() as u64, 0)
            );
            let mut log = RunLog::open_for_append(&path, loaded.valid_len).unwrap();
            for r in lines as u32..3 {
                log.append(&record(r)).unwrap();
            }
            drop(log);
            assert_eq!(std::fs::read_to_string(&path).unwrap(), full);
        }
        let first = record(0).to_json_line();
        std::fs::write(&path, format!("{first}\n \t")).unwrap();
        let loaded = read(&path).unwrap();
        assert_eq!((loaded.records.len(), loaded.torn_bytes), (1, 0));
        assert_eq!(loaded.valid_len, first.len() as u64 + 1);
        for cut in 1..first.len() {
            std::fs::write(&path, &first[..cut]).unwrap();
            let loaded = read(&path).unwrap();
            assert!(
                loaded.records.is_empty(),
                "prefix of {cut} bytes read as a record"
            );
            assert_eq!((loaded.valid_len, loaded.torn_bytes), (0, cut as u64));
        }
    }

    #[test]
    fn corrupt_complete_line_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(RUNS_FILE);
        let mut text = record(0).to_json_line();
        text.push_str("\n{\"mesh\": 1}\n");
        std::fs::write(&path, &text).unwrap();
        let err = read(&path).unwrap_err().to_string();
        assert!(err.contains("line 2"), "{err}");
        // A syntax error names its column, not serde's line within the record.
        text.push_str("{\"mesh\":\"sphere\", broken\n");
        std::fs::write(&path, text.replace("{\"mesh\": 1}\n", "")).unwrap();
        let err = read(&path).unwrap_err().to_string();
        assert!(
            err.ends_with("line 2: key must be a string at column 19"),
            "{err}"
        );
    }

    #[test]
    fn missing_file_is_empty() {
        let dir = tempfile::tempdir().unwrap();
        let loaded = read(&dir.path().join(RUNS_FILE)).unwrap();
        assert!(loaded.records.is_empty());
        assert_eq!(loaded.valid_len, 0);
    }
}
