//! The bitstream end to end: round trips, loss, damage and hostile bytes.

use facemime_core::codec::chunk::{self, Kind};
use facemime_core::codec::{Decoder, Encoder, Header, Output, Quantiser};
use proptest::prelude::*;

fn header(packet_frames: u8, keyframe_packets: u16) -> Header {
    let mut quantisers = vec![
        Quantiser {
            step: 0.2,
            reference: 0,
            class: 6
        };
        6
    ];
    quantisers[3] = Quantiser {
        step: 0.002,
        reference: 1000,
        class: 4,
    };
    quantisers.extend((0..4).map(|i| Quantiser {
        step: 0.5,
        reference: 0,
        class: 5 + i,
    }));
    Header {
        fps_num: 25,
        fps_den: 1,
        width: 512,
        height: 512,
        topology: *b"topology",
        packet_frames,
        keyframe_packets,
        quantisers,
        extras: vec![],
        basis_rows: 6,
        basis: (0..24).map(|i| (i * 1000 - 12000) as i16).collect(),
        actor_id: [7; 32],
        actor_in_stream: false,
    }
}

/// A clip of `n` frames: a drifting head and moving coefficients, with a few faceless frames.
fn clip(n: usize, seed: u64) -> Vec<(bool, u8, Vec<f64>)> {
    let mut x = 0x9e3779b97f4a7c15u64 ^ seed;
    let mut rand = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut v = vec![0.0, 0.0, 0.0, 2.0, 256.0, 256.0, 0.0, 0.0, 0.0, 0.0];
    (0..n)
        .map(|t| {
            for (i, value) in v.iter_mut().enumerate() {
                *value += if i == 3 { 0.003 } else { 1.5 } * rand();
            }
            (t % 37 < 34, (t % 11 == 0) as u8 * 3, v.clone())
        })
        .collect()
}

/// The stream's bytes, and the encoder's reconstruction of every frame.
fn encode(h: &Header, frames: &[(bool, u8, Vec<f64>)]) -> (Vec<Vec<u8>>, Vec<Vec<f64>>) {
    let mut enc = Encoder::new(h.clone(), 0.3).unwrap();
    let mut chunks = vec![enc.header_chunk()];
    let mut recon = Vec::new();
    for (face, lost, v) in frames {
        let (r, packet) = enc.push(*face, *lost, v).unwrap();
        recon.push(r);
        chunks.extend(packet);
    }
    chunks.extend(enc.finish().unwrap());
    (chunks, recon)
}

fn decode(bytes: &[u8], from_start: bool) -> (Decoder, Vec<Output>) {
    let mut d = Decoder::new(from_start);
    let mut out = d.push(bytes);
    out.extend(d.finish());
    (d, out)
}

/// Every decoded frame with a face equals the encoder's reconstruction (a frame without one
/// carries no values: it shows the receiver's last face); returns (decoded, concealed).
fn check(out: &[Output], recon: &[Vec<f64>]) -> (usize, u64) {
    let (mut decoded, mut concealed) = (0, 0);
    for o in out {
        match o {
            Output::Frame {
                index,
                values,
                face,
                ..
            } => {
                if *face {
                    assert_eq!(values, &recon[*index as usize], "frame {index}");
                }
                decoded += 1;
            }
            Output::Concealed { count, .. } => concealed += count,
            Output::Appearance(_) => {}
        }
    }
    (decoded, concealed)
}

#[test]
fn round_trip_gives_the_encoders_reconstruction_bit_for_bit() {
    let h = header(5, 5);
    let frames = clip(503, 1);
    let (chunks, recon) = encode(&h, &frames);
    let (d, out) = decode(&chunks.concat(), true);
    assert_eq!(check(&out, &recon), (503, 0));
    assert_eq!(d.header(), Some(&h));
    let faces: Vec<bool> = out
        .iter()
        .map(|o| matches!(o, Output::Frame { face: true, .. }))
        .collect();
    assert_eq!(faces, frames.iter().map(|f| f.0).collect::<Vec<_>>());
    let lost: Vec<u8> = out
        .iter()
        .map(|o| {
            if let Output::Frame { lost, .. } = o {
                *lost
            } else {
                99
            }
        })
        .collect();
    assert_eq!(lost, frames.iter().map(|f| f.1).collect::<Vec<_>>());
    // the reconstruction is within half a step (plus the hysteresis) of the input
    for ((face, _, v), r) in frames.iter().zip(&recon) {
        if *face {
            for (i, q) in h.quantisers.iter().enumerate() {
                assert!((v[i] - r[i]).abs() <= 0.8 * q.step as f64 + 1e-9);
            }
        }
    }
}

#[test]
fn a_lost_packet_is_concealed_until_the_next_intra_packet() {
    let h = header(5, 4);
    let (chunks, recon) = encode(&h, &clip(200, 2));
    // chunk 0 is the header; packet k is chunk k + 1; drop packet 5 (inter, after intra 4)
    let bytes: Vec<u8> = chunks
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 6)
        .flat_map(|(_, c)| c.clone())
        .collect();
    let (d, out) = decode(&bytes, true);
    // packets 5, 6, 7 (15 frames) are concealed; intra packet 8 resynchronises
    assert_eq!(check(&out, &recon), (185, 15));
    assert_eq!((d.stats.lost_packets, d.stats.concealed), (1, 15));
    assert_eq!(
        out[25..28],
        [
            Output::Concealed {
                first: 25,
                count: 5
            },
            Output::Concealed {
                first: 30,
                count: 5
            },
            Output::Concealed {
                first: 35,
                count: 5
            }
        ]
    );
}

#[test]
fn an_intra_packet_on_request_resynchronises_a_receiver_before_the_schedule_would() {
    let h = header(2, 10);
    let frames = clip(58, 5);
    let mut enc = Encoder::new(h.clone(), 0.3).unwrap();
    let mut chunks = vec![enc.header_chunk()];
    let mut recon = Vec::new();
    for (t, (face, lost, v)) in frames.iter().enumerate() {
        if t == 8 {
            // the receiver lost packet 2 and asks: packet 4 (frames 8-9) is intra, not 10
            enc.request_intra();
            assert!(enc.next_is_intra());
        }
        let (r, packet) = enc.push(*face, *lost, v).unwrap();
        recon.push(r);
        chunks.extend(packet);
    }
    assert!(!enc.next_is_intra(), "a request is answered once");
    let kinds: Vec<u8> = chunks[1..].iter().map(|c| c[0] >> 5).collect();
    let intra: Vec<usize> = (0..kinds.len())
        .filter(|&i| kinds[i] == Kind::Intra as u8)
        .collect();
    assert_eq!(intra, vec![0, 4, 10, 20], "the schedule goes on as before");
    let bytes: Vec<u8> = chunks
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != 3)
        .flat_map(|(_, c)| c.clone())
        .collect();
    let (d, out) = decode(&bytes, true);
    // packets 2 and 3 (4 frames) are concealed; the requested intra packet 4 resynchronises
    assert_eq!(check(&out, &recon), (54, 4));
    assert_eq!((d.stats.lost_packets, d.stats.concealed), (1, 4));
}

#[test]
fn late_and_repeated_packets_are_dropped_and_a_receiver_can_join_mid_stream() {
    let h = header(4, 3);
    let (chunks, recon) = encode(&h, &clip(120, 3));
    let mut order: Vec<usize> = (0..chunks.len()).collect();
    order.swap(8, 9);
    order.insert(12, 3);
    let bytes: Vec<u8> = order.iter().flat_map(|&i| chunks[i].clone()).collect();
    let (d, out) = decode(&bytes, true);
    check(&out, &recon);
    assert_eq!(d.stats.late_packets, 2);
    // joining at packet 4 (inter): concealed until intra packet 6
    let joined: Vec<u8> = std::iter::once(&chunks[0])
        .chain(&chunks[5..])
        .flat_map(|c| c.clone())
        .collect();
    let (_, out) = decode(&joined, false);
    assert_eq!(
        out[0],
        Output::Concealed {
            first: 16,
            count: 4
        }
    );
    assert_eq!(check(&out, &recon), (120 - 24, 8));
}

#[test]
fn a_stream_cut_anywhere_decodes_its_whole_packets() {
    let h = header(5, 5);
    let (chunks, recon) = encode(&h, &clip(60, 4));
    let bytes = chunks.concat();
    for cut in 0..bytes.len() {
        let (_, out) = decode(&bytes[..cut], true);
        check(&out, &recon);
    }
}

#[test]
fn headers_from_other_versions_or_with_absurd_fields_are_refused_with_a_reason() {
    let h = header(5, 5);
    let mut raw = h.to_bytes();
    raw[4] = 3;
    let bytes =
        facemime_core::codec::chunk::write(facemime_core::codec::chunk::Kind::Header, 0, 0, &raw);
    let (d, _) = decode(&bytes, true);
    assert!(d.header().is_none());
    assert_eq!(
        d.header_error(),
        Some("stream format version 3; this decoder reads versions 1 and 2")
    );
    let mut bad = h.clone();
    bad.width = 0;
    assert!(bad.validate().is_err());
    assert!(Header::parse(&h.to_bytes()[..40]).is_err());
    bad = h.clone();
    bad.quantisers[2].step = f32::NAN;
    assert!(Encoder::new(bad, 0.0).is_err());
}

/// `header(5, 5)` with two of its four coefficients turned into extras of kinds 1 and 7.
fn header_with_extras() -> Header {
    let mut h = header(5, 5);
    h.extras = vec![1, 7];
    h.basis.truncate(2 * h.basis_rows as usize);
    h
}

#[test]
fn a_version_2_stream_round_trips_and_a_version_1_header_is_unchanged() {
    let h = header_with_extras();
    let frames = clip(203, 7);
    let (chunks, recon) = encode(&h, &frames);
    let (d, out) = decode(&chunks.concat(), true);
    assert_eq!(check(&out, &recon), (203, 0));
    assert_eq!(d.header().map(|h| h.extras.clone()), Some(vec![1, 7]));
    assert_eq!(d.header().map(Header::coefficients), Some(2));
    // the extras are coded like any parameter: the same values cost the same bytes as
    // coefficients in version 1, give or take the header's three more bytes
    let (v1, _) = encode(&header(5, 5), &frames);
    assert_eq!(v1[1..], chunks[1..]);
    assert_eq!(chunks[0].len(), v1[0].len() - 2 * 2 * 6 + 3);
    assert_eq!((header(5, 5).to_bytes()[4], h.to_bytes()[4]), (1, 2));
}

#[test]
fn a_stream_whose_header_changes_from_version_1_to_2_decodes_both() {
    let (a, recon_a) = encode(&header(5, 5), &clip(30, 8));
    let (b, recon_b) = encode(&header_with_extras(), &clip(30, 9));
    let mut d = Decoder::new(true);
    let mut out = d.push(&a.concat());
    let first = out.len();
    out.extend(d.push(&b.concat()));
    out.extend(d.finish());
    assert_eq!(check(&out[..first], &recon_a), (30, 0));
    assert_eq!(check(&out[first..], &recon_b), (30, 0));
    assert_eq!(d.header().map(|h| h.extras.len()), Some(2));
}

#[test]
fn a_segment_stops_before_a_new_header_so_each_part_has_its_own() {
    let (a, recon_a) = encode(&header(5, 5), &clip(30, 8));
    let (b, recon_b) = encode(&header_with_extras(), &clip(30, 9));
    let mut d = Decoder::new(true);
    // both streams in one piece: the first call ends where the second stream starts
    let out = d.segment(&[a.concat(), b.concat()].concat(), false);
    assert!(d.pending());
    assert_eq!(check(&out, &recon_a), (30, 0));
    assert_eq!(d.header().map(|h| h.extras.len()), Some(0));
    let mut rest = d.segment(&[], false);
    rest.extend(d.segment(&[], true));
    assert!(!d.pending());
    assert_eq!(check(&rest, &recon_b), (30, 0));
    assert_eq!(d.header().map(|h| h.extras.len()), Some(2));
}

#[test]
fn values_beyond_the_formats_range_are_an_error_not_garbage() {
    let mut enc = Encoder::new(header(5, 5), 0.0).unwrap();
    let mut v = clip(1, 5)[0].2.clone();
    v[7] = 1e12;
    assert!(enc.push(true, 0, &v).is_err());
    v[7] = f64::INFINITY;
    assert!(enc.push(true, 0, &v).is_err());
    assert!(enc.push(true, 0, &v[..3]).is_err());
}

/// An appearance payload: first frame `frame`, at (x, y) = (3, 4), then `image` (not parsed).
fn appearance_payload(frame: u32, image: &[u8]) -> Vec<u8> {
    [
        &frame.to_le_bytes()[..],
        &3u16.to_le_bytes(),
        &4u16.to_le_bytes(),
        image,
    ]
    .concat()
}

/// The frames only, and the appearance payloads each with the frames output before it.
fn split(out: Vec<Output>) -> (Vec<Output>, Vec<(u64, Vec<u8>)>) {
    let (mut frames, mut updates, mut seen) = (vec![], vec![], 0);
    for o in out {
        match o {
            Output::Appearance(p) => updates.push((seen, p)),
            Output::Frame { .. } => {
                seen += 1;
                frames.push(o);
            }
            Output::Concealed { count, .. } => {
                seen += count;
                frames.push(o);
            }
        }
    }
    (frames, updates)
}

/// The stream with an appearance chunk before every third packet (for that
/// packet's first frame), and the payloads in order.
fn with_appearance(chunks: &[Vec<u8>], per: u64) -> (Vec<u8>, Vec<(u64, Vec<u8>)>) {
    let (mut bytes, mut updates) = (chunks[0].clone(), vec![]);
    for (s, packet) in chunks[1..].iter().enumerate() {
        if s % 3 == 1 {
            let frame = s as u64 * per;
            let p = appearance_payload(frame as u32, &vec![s as u8; 10 + s]);
            bytes.extend(chunk::appearance(&p).unwrap());
            updates.push((frame, p));
        }
        bytes.extend(packet);
    }
    (bytes, updates)
}

#[test]
fn appearance_chunks_between_packets_change_no_frame_and_come_out_in_order() {
    let h = header(4, 3);
    let (chunks, recon) = encode(&h, &clip(120, 8));
    let (plain, plain_out) = decode(&chunks.concat(), true);
    let (bytes, updates) = with_appearance(&chunks, 4);
    assert_eq!(updates.len(), 10);
    for piece in [bytes.len(), 7, 1] {
        let mut d = Decoder::new(true);
        let mut out = Vec::new();
        for p in bytes.chunks(piece) {
            out.extend(d.push(p));
        }
        out.extend(d.finish());
        let (frames, got) = split(out);
        assert_eq!(frames, plain_out);
        // each comes out where it was read: just before its packet's frames
        assert_eq!(got, updates);
        assert_eq!(check(&frames, &recon), (120, 0));
        let mut stats = d.stats.clone();
        assert_eq!(stats.appearance, 10);
        stats.appearance = 0;
        assert_eq!(stats, plain.stats);
    }
}

#[test]
fn a_damaged_appearance_chunk_is_skipped_as_damage_and_the_rest_decodes() {
    let h = header(4, 3);
    let (chunks, recon) = encode(&h, &clip(60, 9));
    let (_, plain_out) = decode(&chunks.concat(), true);
    let (bytes, updates) = with_appearance(&chunks, 4);
    // flip a byte of the first update's image
    let at = chunks[0].len() + chunks[1].len() + 4 + 8 + 3;
    assert_eq!(bytes[at], 1);
    let mut damaged = bytes.clone();
    damaged[at] ^= 0x40;
    let (d, out) = decode(&damaged, true);
    let (frames, got) = split(out);
    assert_eq!(frames, plain_out);
    assert_eq!(check(&frames, &recon), (60, 0));
    assert_eq!(got, updates[1..]);
    assert_eq!((d.stats.damaged_runs, d.stats.undecodable), (1, 0));
    assert_eq!(d.stats.appearance, updates.len() as u64 - 1);
}

#[test]
fn a_short_appearance_payload_or_one_before_the_header_is_undecodable() {
    let h = header(4, 3);
    let (chunks, recon) = encode(&h, &clip(20, 10));
    let short = chunk::write(Kind::Appearance, 0, 0, &[1, 2, 3, 4, 5, 6, 7]);
    let good = chunk::appearance(&appearance_payload(0, b"RIFF")).unwrap();
    let bytes = [
        good.clone(),
        chunks[0].clone(),
        short,
        good.clone(),
        chunks[1..].concat(),
    ]
    .concat();
    let (d, out) = decode(&bytes, true);
    let (frames, got) = split(out);
    assert_eq!(check(&frames, &recon), (20, 0));
    assert_eq!(got, vec![(0, appearance_payload(0, b"RIFF"))]);
    assert_eq!((d.stats.undecodable, d.stats.appearance), (2, 1));
    assert_eq!(d.stats.damaged_runs, 0);
}

#[test]
fn an_appearance_chunk_declaring_more_than_a_mebibyte_is_not_a_chunk() {
    let h = header(4, 3);
    let (chunks, recon) = encode(&h, &clip(20, 11));
    // the tag, seq, and a length of 2^20 + 1: damage; the reader resynchronises after it
    let n = (1usize << 20) + 1;
    let fake = [5 << 5, 0, 0, (n & 0x7f) as u8 | 0x80, 0x80, (n >> 14) as u8];
    let bytes = [chunks[0].clone(), fake.to_vec(), chunks[1..].concat()].concat();
    let (d, out) = decode(&bytes, true);
    let (frames, got) = split(out);
    assert_eq!(check(&frames, &recon), (20, 0));
    assert!(got.is_empty());
    assert_eq!((d.stats.damaged_runs, d.stats.damaged_bytes), (1, 6));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let (d, out) = decode(&bytes, true);
        prop_assert!(out.is_empty() || d.header().is_some());
    }

    #[test]
    fn mutated_streams_never_decode_garbage(edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..4), 1..8),
                                            pieces in 1usize..7) {
        let h = header(3, 4);
        let (chunks, recon) = encode(&h, &clip(90, 6));
        let (mut bytes, updates) = with_appearance(&chunks, 3);
        for (at, value, how) in edits {
            let i = at.index(bytes.len());
            match how {
                0 => bytes[i] ^= value | 1,
                1 => { bytes.remove(i); }
                2 => bytes.insert(i, value),
                _ => { bytes.truncate(i); if bytes.is_empty() { break; } }
            }
            if bytes.is_empty() { break; }
        }
        // fed in pieces, as a network delivers it
        let mut d = Decoder::new(true);
        let step = bytes.len() / pieces + 1;
        let mut out = Vec::new();
        for piece in bytes.chunks(step) {
            out.extend(d.push(piece));
        }
        out.extend(d.finish());
        check(&out, &recon);
        // an update that comes out is one that was sent, whole
        for (_, p) in split(out).1 {
            prop_assert!(updates.iter().any(|(_, u)| *u == p));
        }
    }
}
