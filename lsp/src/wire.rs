//! The wire of `sdfc lsp`: messages framed by `Content-Length` headers, read from any byte
//! stream and classified, every malformed one reported and skipped (never the end of the
//! stream), and messages written to any sink.
//!
//! Reading never allocates more than the bytes that arrived: a body is collected as it comes,
//! up to [`message_limit`]; a longer one is discarded as it comes. After a malformed header the
//! reader skips to the next `Content-Length:`, and a body ends early where `Content-Length:`
//! begins outside a JSON string (JSON text has no such bytes there: it is the next message's
//! header), so that a message whose `Content-Length` says too much does not swallow the next.
//! Header lines may end with CRLF (as the protocol says) or LF alone.

use lsp_server::{ErrorCode, Message, Notification, Request, RequestId};
use serde_json::{value::RawValue, Value};
use std::io::{self, BufRead, Write};

/// The largest body of one message, in bytes: twice the `file_size` limit (a document of
/// that size, its JSON escapes and the message around it fit).
pub fn message_limit(limits: &sdfc_compiler::Limits) -> u64 {
    limits
        .get(sdfc_compiler::Limit::FileSize)
        .saturating_mul(2 << 20)
}

/// The longest header line kept; a longer one is malformed (and skipped as it comes).
const LINE_LIMIT: usize = 1024;

/// What starts a header block, compared without regard to case.
const HEADER: &[u8] = b"content-length:";

/// Why bytes of the input do not frame a message.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// A header line is not `Name: value`.
    #[error("a header line is not `Name: value`: `{line}`")]
    NotAHeader {
        /// The line (its first bytes, as text).
        line: String,
    },
    /// The headers end without a `Content-Length`.
    #[error("the headers have no Content-Length")]
    NoLength,
    /// The `Content-Length` is not a byte count.
    #[error("Content-Length `{value}` is not a number of bytes")]
    BadLength {
        /// The value written.
        value: String,
    },
    /// The body is longer than the limit ([`message_limit`]).
    #[error("a message of {length} bytes is over the limit of {limit} bytes (twice the file_size limit)")]
    TooLong {
        /// Its `Content-Length`.
        length: u64,
        /// The limit.
        limit: u64,
    },
    /// A header of the next message began before the body's `Content-Length` bytes had.
    #[error("the body ends after {found} of the {length} bytes its Content-Length says, where the next message's header begins")]
    Short {
        /// Its `Content-Length`.
        length: u64,
        /// The bytes before the next header.
        found: usize,
    },
    /// The input ended inside a message.
    #[error("the input ends inside a message")]
    Truncated,
}

/// One step of the input: a body to parse, or bytes that frame none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Frame {
    /// The bytes of one message's body.
    Body(Vec<u8>),
    /// Bytes that frame no message, skipped up to the next header.
    Bad(FrameError),
}

/// Reads frames from `input`.
#[derive(Debug)]
pub struct Reader<R> {
    input: R,
    /// Bytes read ahead of the input (the start of a header found inside a body), read first.
    ahead: Vec<u8>,
    /// Whether the last frame was bad and the input is being skipped to the next header.
    skipping: bool,
    limit: u64,
}

impl<R: BufRead> Reader<R> {
    /// A reader of `input` with bodies up to `limit` bytes.
    pub fn with_limit(input: R, limit: u64) -> Reader<R> {
        Reader {
            input,
            ahead: Vec::new(),
            skipping: false,
            limit,
        }
    }

    /// The next byte, `None` at the end of the input.
    fn byte(&mut self) -> io::Result<Option<u8>> {
        let b = if let Some(b) = self.ahead.pop() {
            b
        } else {
            let buf = loop {
                match self.input.fill_buf() {
                    Ok(buf) => break buf,
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                    Err(e) => return Err(e),
                }
            };
            let Some(&b) = buf.first() else {
                return Ok(None);
            };
            self.input.consume(1);
            b
        };
        Ok(Some(b))
    }

    /// Puts `bytes` back, to be read next.
    fn unread(&mut self, bytes: &[u8]) {
        self.ahead.extend(bytes.iter().rev());
    }

    /// Reads up to `length` bytes, keeping them when `keep` (else discarding them), and stops
    /// early where `Content-Length:` begins outside a JSON string (where no JSON text has it:
    /// the next message's header). The bytes kept, how many were read, and why it stopped.
    fn body(&mut self, length: u64, keep: bool) -> io::Result<(Vec<u8>, u64, Stop)> {
        let mut out = Vec::new();
        let mut read = 0u64;
        // Bytes of a possible header, held back until they differ from it.
        let mut held: Vec<u8> = Vec::new();
        let (mut string, mut escaped) = (false, false);
        while read < length {
            let Some(b) = self.byte()? else {
                return Ok((out, read, Stop::End));
            };
            read += 1;
            if !string {
                if b.to_ascii_lowercase() == HEADER[held.len()] {
                    held.push(b);
                    if held.len() == HEADER.len() {
                        read -= held.len() as u64;
                        self.unread(&held);
                        return Ok((out, read, Stop::Header));
                    }
                    continue;
                }
                if keep {
                    out.extend_from_slice(&held);
                }
                held.clear();
                if b.to_ascii_lowercase() == HEADER[0] {
                    held.push(b);
                    continue;
                }
            }
            if string {
                if escaped {
                    escaped = false;
                } else if b == b'\\' {
                    escaped = true;
                } else if b == b'"' {
                    string = false;
                }
            } else if b == b'"' {
                string = true;
            }
            if keep {
                out.push(b);
            }
        }
        if keep {
            out.extend_from_slice(&held);
        }
        Ok((out, read, Stop::Length))
    }

    /// Skips to the next `Content-Length:` (anywhere: after a malformed header the bytes are
    /// not known to be JSON); `false` at the end of the input.
    fn skip_to_header(&mut self) -> io::Result<bool> {
        let mut matched = 0;
        loop {
            let Some(b) = self.byte()? else {
                return Ok(false);
            };
            let b = b.to_ascii_lowercase();
            if b == HEADER[matched] {
                matched += 1;
                if matched == HEADER.len() {
                    self.unread(b"Content-Length:");
                    return Ok(true);
                }
            } else {
                matched = usize::from(b == HEADER[0]);
            }
        }
    }

    /// One header line without its line ending (at most [`LINE_LIMIT`] bytes kept), `None`
    /// at the end of the input; `Err(true)` when the input ended inside it.
    fn line(&mut self) -> io::Result<Result<Vec<u8>, bool>> {
        let mut line = Vec::new();
        loop {
            match self.byte()? {
                None => return Ok(Err(!line.is_empty())),
                Some(b'\n') => {
                    if line.last() == Some(&b'\r') {
                        line.pop();
                    }
                    return Ok(Ok(line));
                }
                Some(b) => {
                    if line.len() <= LINE_LIMIT {
                        line.push(b);
                    }
                }
            }
        }
    }

    /// The next frame; `None` at the end of the input.
    pub fn next_frame(&mut self) -> io::Result<Option<Frame>> {
        if std::mem::take(&mut self.skipping) && !self.skip_to_header()? {
            return Ok(None);
        }
        let bad = |reader: &mut Self, e: FrameError| {
            reader.skipping = true;
            Ok(Some(Frame::Bad(e)))
        };
        let mut length: Option<u64> = None;
        let mut any = false;
        loop {
            let line = match self.line()? {
                Ok(line) => line,
                Err(false) if !any => return Ok(None),
                Err(_) => return Ok(Some(Frame::Bad(FrameError::Truncated))),
            };
            if line.is_empty() {
                if any {
                    break;
                }
                // Blank lines between messages are skipped.
                continue;
            }
            any = true;
            let text = String::from_utf8_lossy(&line[..line.len().min(LINE_LIMIT)]).into_owned();
            let header = text
                .split_once(':')
                .filter(|(name, _)| !name.is_empty() && name.bytes().all(token_byte));
            let Some((name, value)) = header else {
                // The next header may begin inside the line (after a body shorter than its
                // Content-Length said): the skip reads it again, all but its first byte.
                self.unread(b"\n");
                self.unread(&line[1..line.len().min(LINE_LIMIT)]);
                return bad(self, FrameError::NotAHeader { line: text });
            };
            if name.trim().eq_ignore_ascii_case("content-length") {
                let value = value.trim();
                match value.parse::<u64>() {
                    Ok(n) if line.len() <= LINE_LIMIT => length = Some(n),
                    _ => {
                        return bad(
                            self,
                            FrameError::BadLength {
                                value: value.to_string(),
                            },
                        )
                    }
                }
            }
        }
        let Some(length) = length else {
            return bad(self, FrameError::NoLength);
        };
        if length > self.limit {
            // Discarded as it comes, up to the next header.
            self.body(length, false)?;
            return Ok(Some(Frame::Bad(FrameError::TooLong {
                length,
                limit: self.limit,
            })));
        }
        let (body, read, stop) = self.body(length, true)?;
        Ok(Some(match stop {
            Stop::Length => Frame::Body(body),
            Stop::Header => Frame::Bad(FrameError::Short {
                length,
                found: read as usize,
            }),
            Stop::End => Frame::Bad(FrameError::Truncated),
        }))
    }
}

/// Whether `b` may be part of a header's name (an HTTP token).
fn token_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b)
}

/// Why [`Reader::body`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stop {
    /// It read the length asked for.
    Length,
    /// A header began.
    Header,
    /// The input ended.
    End,
}

/// A message read: one to handle, or one to refuse with an error response.
#[derive(Debug, Clone)]
pub enum Incoming {
    /// A request, notification or response.
    Message(Message),
    /// Something that is not a message the server can handle: the response it gets.
    Refused {
        /// The id to answer, as it was written (`null` when there is none or it cannot be
        /// read).
        id: Box<RawValue>,
        /// The JSON-RPC error code.
        code: i32,
        /// What was wrong.
        message: String,
    },
}

/// JSON `null`, the id of an answer to a message whose id is not known.
pub fn null() -> Box<RawValue> {
    Box::<RawValue>::default()
}

impl Incoming {
    fn refused(id: Box<RawValue>, code: ErrorCode, message: impl Into<String>) -> Incoming {
        Incoming::Refused {
            id,
            code: code as i32,
            message: message.into(),
        }
    }
}

/// What a frame holds: a message, or the error response its sender gets (a parse error for
/// bytes that are not JSON, an invalid request for JSON that is not a message the protocol
/// allows: a batch, an id that is neither a string nor a 32-bit integer).
pub fn classify(frame: Frame) -> Incoming {
    let body = match frame {
        Frame::Body(body) => body,
        Frame::Bad(e) => return Incoming::refused(null(), ErrorCode::ParseError, e.to_string()),
    };
    let value: Value = match serde_json::from_slice(&body) {
        Ok(v) => v,
        Err(e) => {
            let why = match std::str::from_utf8(&body) {
                Err(u) => format!(
                    "the message is not UTF-8 (first bad byte at offset {})",
                    u.valid_up_to()
                ),
                Ok(_) => format!("the message is not JSON: {e}"),
            };
            return Incoming::refused(null(), ErrorCode::ParseError, why);
        }
    };
    let Value::Object(mut object) = value else {
        let why = if value.is_array() {
            "batches of messages are not supported: send them one by one"
        } else {
            "a message must be a JSON object"
        };
        return Incoming::refused(null(), ErrorCode::InvalidRequest, why);
    };
    // The id as written (a number such as 2⁷⁰ does not survive as a `Value`).
    #[derive(serde::Deserialize)]
    struct Raw {
        id: Option<Box<RawValue>>,
    }
    let answer_id = serde_json::from_slice::<Raw>(&body)
        .ok()
        .and_then(|r| r.id)
        .unwrap_or_else(null);
    let id = match object.remove("id") {
        None => None,
        Some(v) => match request_id(&v) {
            Some(id) => Some(id),
            None => {
                let why = format!(
                    "the id {} is neither a string nor an integer of 32 bits",
                    answer_id.get()
                );
                return Incoming::refused(answer_id, ErrorCode::InvalidRequest, why);
            }
        },
    };
    let params = object.remove("params").unwrap_or(Value::Null);
    match (object.remove("method"), id) {
        (Some(Value::String(method)), Some(id)) => {
            Incoming::Message(Message::Request(Request { id, method, params }))
        }
        (Some(Value::String(method)), None) => {
            Incoming::Message(Message::Notification(Notification { method, params }))
        }
        (Some(_), _) => Incoming::refused(
            answer_id,
            ErrorCode::InvalidRequest,
            "the method must be a string",
        ),
        // A response (the server sends no requests, so it answers none of them).
        (None, Some(id)) if object.contains_key("result") || object.contains_key("error") => {
            Incoming::Message(Message::Response(lsp_server::Response {
                id,
                response_result: Ok(Value::Null),
            }))
        }
        (None, _) => Incoming::refused(
            answer_id,
            ErrorCode::InvalidRequest,
            "a message must have a method (or be a response)",
        ),
    }
}

/// The id of a request: a string or an integer of 32 bits, as the protocol allows.
fn request_id(v: &Value) -> Option<RequestId> {
    match v {
        Value::String(s) => Some(RequestId::from(s.clone())),
        Value::Number(n) => n
            .as_i64()
            .and_then(|n| i32::try_from(n).ok())
            .map(RequestId::from),
        _ => None,
    }
}

/// Writes `message` framed (with `"jsonrpc": "2.0"`) and flushes.
pub fn write(out: &mut impl Write, message: &Message) -> io::Result<()> {
    // Serialised once, the member put first in its text: through a `Value` the message's
    // whole tree was copied (a megabyte's outline of symbols took a second).
    let text = serde_json::to_vec(message)?;
    let rest = text.strip_prefix(b"{").unwrap_or(&text);
    let mut framed = Vec::with_capacity(text.len() + 17);
    framed.extend_from_slice(b"{\"jsonrpc\":\"2.0\"");
    if rest != b"}" {
        framed.push(b',');
    }
    framed.extend_from_slice(rest);
    write_text(out, &framed)
}

/// Writes an error response to `id` (any JSON: `null` when unknown), framed, and flushes.
pub fn write_error(
    out: &mut impl Write,
    id: &RawValue,
    code: i32,
    message: &str,
) -> io::Result<()> {
    #[derive(serde::Serialize)]
    struct Error<'a> {
        code: i32,
        message: &'a str,
    }
    // Serialised directly: through a `Value` an id such as 2⁷⁰ would be rounded.
    #[derive(serde::Serialize)]
    struct Answer<'a> {
        jsonrpc: &'static str,
        id: &'a RawValue,
        error: Error<'a>,
    }
    let answer = Answer {
        jsonrpc: "2.0",
        id,
        error: Error { code, message },
    };
    write_text(out, &serde_json::to_vec(&answer)?)
}

fn write_text(out: &mut impl Write, text: &[u8]) -> io::Result<()> {
    write!(out, "Content-Length: {}\r\n\r\n", text.len())?;
    out.write_all(text)?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(input: &[u8], limit: u64) -> Vec<Frame> {
        let mut r = Reader::with_limit(input, limit);
        let mut out = Vec::new();
        while let Some(f) = r.next_frame().expect("reading a slice") {
            out.push(f);
        }
        out
    }

    fn msg(body: &str) -> String {
        format!("Content-Length: {}\r\n\r\n{body}", body.len())
    }

    /// `bad` followed by a good message reads as the frame refused with `error`, then the
    /// message.
    #[track_caller]
    fn assert_bad_then_good(bad: &str, error: FrameError) {
        let input = format!("{bad}{}", msg("{}"));
        assert_eq!(
            frames(input.as_bytes(), 100),
            vec![Frame::Bad(error), Frame::Body(b"{}".to_vec())],
            "{bad:?}"
        );
    }

    #[test]
    fn frames_with_crlf_or_lf_and_any_case() {
        let input = format!(
            "{}content-length: 2\n\n{{}}\r\n{}",
            msg("[1]"),
            msg("{\"a\":1}")
        );
        assert_eq!(
            frames(input.as_bytes(), 100),
            vec![
                Frame::Body(b"[1]".to_vec()),
                Frame::Body(b"{}".to_vec()),
                Frame::Body(b"{\"a\":1}".to_vec())
            ]
        );
    }

    #[test]
    fn malformed_headers_are_reported_and_skipped_to_the_next_message() {
        let cases: &[(&str, FrameError)] = &[
            (
                "Content-Length: -5\r\n\r\n{}",
                FrameError::BadLength { value: "-5".into() },
            ),
            (
                "Content-Length: many\r\n\r\n{}",
                FrameError::BadLength {
                    value: "many".into(),
                },
            ),
            ("Content-Type: x\r\n\r\n{}", FrameError::NoLength),
            (
                "garbage\r\n",
                FrameError::NotAHeader {
                    line: "garbage".into(),
                },
            ),
            (
                "Content-Length: 99999999999999999999999\r\n\r\n",
                FrameError::BadLength {
                    value: "99999999999999999999999".into(),
                },
            ),
        ];
        for (bad, error) in cases {
            assert_bad_then_good(bad, error.clone());
        }
    }

    #[test]
    fn a_long_length_stops_at_the_next_header_and_a_huge_one_is_not_kept() {
        let good = msg("{}");
        assert_bad_then_good(
            "Content-Length: 50\r\n\r\n{\"a\":\n",
            FrameError::Short {
                length: 50,
                found: 6,
            },
        );
        assert_bad_then_good(
            "Content-Length: 1000000000000\r\n\r\n",
            FrameError::TooLong {
                length: 1_000_000_000_000,
                limit: 100,
            },
        );
        // A short length leaves the rest of the body, which is skipped as a bad header.
        let input = format!("Content-Length: 1\r\n\r\n{{\"a\":1}}\r\n{good}");
        let got = frames(input.as_bytes(), 100);
        assert_eq!(got.first(), Some(&Frame::Body(b"{".to_vec())));
        assert_eq!(got.last(), Some(&Frame::Body(b"{}".to_vec())));
        assert_eq!(
            frames(b"Content-Length: 9\r\n\r\n{}", 100),
            vec![Frame::Bad(FrameError::Truncated)]
        );
    }

    #[test]
    fn classifies_what_is_not_a_message() {
        let refused = |body: &[u8]| match classify(Frame::Body(body.to_vec())) {
            Incoming::Refused { id, code, .. } => (id.get().to_string(), code),
            Incoming::Message(m) => panic!("{m:?} from {body:?}"),
        };
        let parse = ErrorCode::ParseError as i32;
        let invalid = ErrorCode::InvalidRequest as i32;
        let null = || "null".to_string();
        assert_eq!(refused(b"{\"id\":1,"), (null(), parse));
        assert_eq!(refused(b"\xff\xfe"), (null(), parse));
        assert_eq!(refused(b"[{\"id\":1}]"), (null(), invalid));
        assert_eq!(refused(b"7"), (null(), invalid));
        assert_eq!(
            refused(b"{\"id\":1.5,\"method\":\"x\"}"),
            ("1.5".into(), invalid)
        );
        assert_eq!(
            refused(b"{\"id\":1180591620717411303424,\"method\":\"x\"}"),
            ("1180591620717411303424".into(), invalid)
        );
        assert_eq!(refused(b"{\"id\":3,\"method\":4}"), ("3".into(), invalid));
        assert!(matches!(
            classify(Frame::Body(b"{\"id\":\"a\",\"method\":\"m\"}".to_vec())),
            Incoming::Message(Message::Request(_))
        ));
    }
}
