//! What an intruder on the cell's network has: a packet capture of every UDP datagram on the
//! test's network namespace (an `AF_PACKET` socket, as tcpdump opens one; needs root, which
//! `scripts/test.sh` has), a reading of RTPS messages good enough to find the DATA submessages
//! in them, and RTPS messages of its own making, sent from a plain UDP socket.
#![allow(dead_code)]

use std::net::{Ipv4Addr, SocketAddrV4, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// One UDP datagram seen on the wire.
#[derive(Clone, Debug)]
pub struct Datagram {
    pub src: SocketAddrV4,
    pub dst: SocketAddrV4,
    pub payload: Vec<u8>,
}

/// A running capture of every IPv4 UDP datagram of the namespace.
pub struct Capture {
    seen: Arc<Mutex<Vec<Datagram>>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

const ETH_P_IP: u16 = 0x0800;

impl Capture {
    /// Starts capturing; panics if the packet socket cannot be opened (not root).
    pub fn start() -> Capture {
        // SAFETY: plain socket calls on a descriptor this function owns.
        let fd = unsafe {
            libc::socket(
                libc::AF_PACKET,
                libc::SOCK_DGRAM,
                i32::from(ETH_P_IP.to_be()),
            )
        };
        assert!(
            fd >= 0,
            "packet capture needs root (AF_PACKET): {}",
            std::io::Error::last_os_error()
        );
        let timeout = libc::timeval {
            tv_sec: 0,
            tv_usec: 100_000,
        };
        // SAFETY: `timeout` outlives the call; the size is its own.
        unsafe {
            libc::setsockopt(
                fd,
                libc::SOL_SOCKET,
                libc::SO_RCVTIMEO,
                (&timeout as *const libc::timeval).cast(),
                std::mem::size_of::<libc::timeval>() as libc::socklen_t,
            );
        }
        let seen = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let (s, st) = (seen.clone(), stop.clone());
        let thread = std::thread::spawn(move || {
            let mut buf = vec![0u8; 70_000];
            while !st.load(Ordering::Relaxed) {
                // SAFETY: zeroed sockaddr_ll is a valid value; sizes are the buffers' own.
                let mut from: libc::sockaddr_ll = unsafe { std::mem::zeroed() };
                let mut len = std::mem::size_of::<libc::sockaddr_ll>() as libc::socklen_t;
                let n = unsafe {
                    libc::recvfrom(
                        fd,
                        buf.as_mut_ptr().cast(),
                        buf.len(),
                        0,
                        (&mut from as *mut libc::sockaddr_ll).cast(),
                        &mut len,
                    )
                };
                // Loopback shows each packet twice, leaving and arriving: keep the arrival.
                if n <= 0 || from.sll_pkttype == libc::PACKET_OUTGOING {
                    continue;
                }
                if let Some(d) = udp_of_ipv4(&buf[..n as usize]) {
                    s.lock().expect("capture").push(d);
                }
            }
            // SAFETY: the descriptor is this thread's alone by now.
            unsafe { libc::close(fd) };
        });
        Capture {
            seen,
            stop,
            thread: Some(thread),
        }
    }

    /// Stops the capture: every datagram seen.
    pub fn stop(mut self) -> Vec<Datagram> {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        std::mem::take(&mut *self.seen.lock().expect("capture"))
    }
}

fn udp_of_ipv4(p: &[u8]) -> Option<Datagram> {
    let ihl = usize::from(p.first()? & 0x0f) * 4;
    if p.first()? >> 4 != 4 || *p.get(9)? != 17 || p.len() < ihl + 8 {
        return None;
    }
    let addr = |at: usize| Ipv4Addr::new(p[at], p[at + 1], p[at + 2], p[at + 3]);
    let port = |at: usize| u16::from_be_bytes([p[at], p[at + 1]]);
    let udp_len = usize::from(port(ihl + 4));
    let end = (ihl + udp_len).min(p.len());
    Some(Datagram {
        src: SocketAddrV4::new(addr(12), port(ihl)),
        dst: SocketAddrV4::new(addr(16), port(ihl + 2)),
        payload: p.get(ihl + 8..end)?.to_vec(),
    })
}

/// The sender's GUID prefix of an RTPS message.
pub fn rtps_sender(payload: &[u8]) -> Option<[u8; 12]> {
    if payload.get(..4)? != b"RTPS" {
        return None;
    }
    payload.get(8..20)?.try_into().ok()
}

/// A DATA submessage found in a message: its writer's entity id and sequence number.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DataSeen {
    pub writer: [u8; 4],
    pub seq: i64,
}

const DATA: u8 = 0x15;
const INFO_DST: u8 = 0x0e;

/// Every DATA submessage of an RTPS message that is readable on the wire (not inside an
/// encrypted body).
pub fn data_submessages(payload: &[u8]) -> Vec<DataSeen> {
    let mut out = Vec::new();
    let mut at = 20;
    while at + 4 <= payload.len() {
        let (id, flags) = (payload[at], payload[at + 1]);
        let le = flags & 1 == 1;
        let raw = [payload[at + 2], payload[at + 3]];
        let len = usize::from(if le {
            u16::from_le_bytes(raw)
        } else {
            u16::from_be_bytes(raw)
        });
        let body = &payload[at + 4..payload.len().min(at + 4 + len)];
        if id == DATA && body.len() >= 20 {
            let word = |b: &[u8]| -> [u8; 4] { [b[0], b[1], b[2], b[3]] };
            let int = |b: [u8; 4]| {
                if le {
                    u32::from_le_bytes(b)
                } else {
                    u32::from_be_bytes(b)
                }
            };
            let high = i64::from(int(word(&body[12..16])) as i32);
            let low = i64::from(int(word(&body[16..20])));
            out.push(DataSeen {
                writer: word(&body[8..12]),
                seq: (high << 32) | low,
            });
        }
        if len == 0 {
            break;
        }
        at += 4 + len;
    }
    out
}

/// An RTPS message as `sender` would send it: one DATA of `writer` with sequence number `seq`
/// to every reader (reader id unknown) carrying `payload` (with its CDR encapsulation), after
/// an INFO_DST naming `destination` if given. Nothing in it is signed or encrypted.
pub fn forged_data(
    sender: [u8; 12],
    destination: Option<[u8; 12]>,
    writer: [u8; 4],
    seq: i64,
    payload: &[u8],
) -> Vec<u8> {
    let mut m = b"RTPS".to_vec();
    m.extend_from_slice(&[2, 4, 0x01, 0x12]);
    m.extend_from_slice(&sender);
    if let Some(dst) = destination {
        m.extend_from_slice(&[INFO_DST, 0x01, 12, 0]);
        m.extend_from_slice(&dst);
    }
    let padding = (4 - payload.len() % 4) % 4;
    let len = 20 + payload.len() + padding;
    m.extend_from_slice(&[DATA, 0x05]); // little endian, data present
    m.extend_from_slice(&(len as u16).to_le_bytes());
    m.extend_from_slice(&[0, 0, 16, 0]); // extra flags, octets to inline QoS
    m.extend_from_slice(&[0, 0, 0, 0]); // reader: unknown, i.e. every matched reader
    m.extend_from_slice(&writer);
    m.extend_from_slice(&((seq >> 32) as i32).to_le_bytes());
    m.extend_from_slice(&(seq as u32).to_le_bytes());
    m.extend_from_slice(payload);
    m.extend(std::iter::repeat_n(0u8, padding));
    m
}

/// A CDR (little-endian) encapsulated sample of `value`, as a ROS 2 writer sends it.
pub fn cdr_sample<T: serde::Serialize>(value: &T) -> Vec<u8> {
    let mut out = vec![0x00, 0x01, 0x00, 0x00];
    out.extend(cdr_encoding::to_vec::<_, byteorder::LittleEndian>(value).expect("cdr"));
    out
}

/// Sends each datagram's payload to its destination from a plain socket of this host, as an
/// intruder without credentials can.
pub fn send_all<'a>(datagrams: impl IntoIterator<Item = (&'a [u8], SocketAddrV4)>) -> usize {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("a plain UDP socket");
    let mut sent = 0;
    for (payload, dst) in datagrams {
        if socket.send_to(payload, dst).is_ok() {
            sent += 1;
        }
    }
    sent
}
