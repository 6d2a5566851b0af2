//! The message service's file output (`001` §8.4.4): a program's `MSG("File: …")` texts as
//! lines of a file kept to its largest size as a ring, the oldest lines dropped ("达到最大大小
//! 时，文件被描述为环形缓冲器，即新信息在文件末尾写入，并在文件开始处删除相应的行").

use std::path::Path;

/// `text` with `line` appended, its oldest lines dropped until it fits `max_bytes` (a line
/// longer than that alone is cut to it).
pub fn ring_append(text: &str, line: &str, max_bytes: usize) -> String {
    let line: String = line.replace(['\n', '\r'], " ");
    let mut out = String::with_capacity(text.len() + line.len() + 1);
    out.push_str(text);
    out.push_str(&line);
    out.push('\n');
    while out.len() > max_bytes {
        match out.find('\n') {
            Some(i) if i + 1 < out.len() => {
                out.drain(..=i);
            }
            _ => {
                let mut cut = max_bytes.saturating_sub(1);
                while cut > 0 && !out.is_char_boundary(cut) {
                    cut -= 1;
                }
                out.truncate(cut);
                out.push('\n');
                break;
            }
        }
    }
    out
}

/// Appends `line` to the file at `path`, kept to `max_kib`: written durably to a new file and
/// renamed over the old ([`cnc_runtime::persist::write_atomic`]), so a crash leaves the old or
/// the new, never half of one.
pub fn append(path: &Path, line: &str, max_kib: u32) -> Result<(), String> {
    let old = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let new = ring_append(&old, line, max_kib as usize * 1024);
    cnc_runtime::persist::write_atomic(path, &new)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_keeps_its_newest_lines_within_its_size() {
        let mut t = String::new();
        for k in 0..10 {
            t = ring_append(&t, &format!("line {k}"), 30);
        }
        assert!(t.len() <= 30, "{t:?}");
        assert!(t.ends_with("line 9\n"), "{t:?}");
        assert!(t.starts_with("line "), "{t:?}");
        // A text with a line break stays one line; one longer than the file is cut to it.
        assert_eq!(ring_append("", "a\nb", 100), "a b\n");
        assert_eq!(ring_append("x\n", &"y".repeat(50), 10).len(), 10);
    }

    #[test]
    fn appending_writes_the_file_whole() {
        let dir = std::env::temp_dir().join(format!("cnc_msg_{}", std::process::id()));
        let _ = std::fs::create_dir_all(&dir);
        let file = dir.join("msg.txt");
        let _ = std::fs::remove_file(&file);
        append(&file, "轮廓粗加工", 10).unwrap();
        append(&file, "second", 10).unwrap();
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            "轮廓粗加工\nsecond\n"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
