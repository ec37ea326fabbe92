//! Segment life cycle across processes: stale segments are replaced, live ones refused,
//! mismatching layouts refused with both values named, a dead CNC's heartbeat stops.

use hli_transport::segment::{
    AttachError, CncSegment, CreateError, HeartbeatWatch, LayoutIdentity, PeerLiveness, PlcSegment,
};
use std::time::Duration;
use tests::{unique_instance, ChildGuard};

fn spawn_peer(mode: &str, instance: &str) -> ChildGuard {
    tests::spawn_ready_peer(env!("CARGO_BIN_EXE_hli-peer"), mode, instance)
}

#[test]
fn stale_segment_of_a_crashed_cnc_is_replaced() {
    let instance = unique_instance("stale");
    let mut child = spawn_peer("cnc-crash", &instance);
    let pid = child.0.id();
    let status = child.wait_with_watchdog(Duration::from_secs(30)).unwrap();
    assert!(!status.success(), "the peer aborts");
    // The object is still there, left behind by the crash.
    assert!(matches!(
        PlcSegment::attach(&instance),
        Ok(_) | Err(AttachError::NotReady { .. })
    ));
    let segment = CncSegment::create(&instance, 2, 3).unwrap();
    assert_eq!(segment.replaced_stale().map(|s| s.pid), Some(pid));
    let plc = PlcSegment::attach(&instance).unwrap();
    assert_eq!((plc.channel_count(), plc.axis_count()), (2, 3));
}

#[test]
fn live_segment_is_not_taken_over_and_its_heartbeat_stops_when_the_cnc_dies() {
    let instance = unique_instance("live");
    let mut child = spawn_peer("cnc-beat", &instance);
    match CncSegment::create(&instance, 1, 1) {
        Err(CreateError::InUse { pid, .. }) => assert_eq!(pid, child.0.id()),
        other => panic!("expected InUse, got {other:?}"),
    }
    let plc = PlcSegment::attach(&instance).unwrap();
    assert!(plc.cnc_process_alive());
    let mut watch = HeartbeatWatch::new(5);
    // Observe until the beat moves (bounded by the child's watchdog via ChildGuard).
    let mut liveness = watch.observe(plc.cnc_heartbeat());
    for _ in 0..10_000 {
        if liveness == PeerLiveness::Alive {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
        liveness = watch.observe(plc.cnc_heartbeat());
    }
    assert_eq!(liveness, PeerLiveness::Alive);

    child.0.kill().unwrap();
    child
        .wait_with_watchdog(Duration::from_secs(30))
        .expect("watchdog: the killed peer was not reaped");
    let verdicts: Vec<_> = (0..6).map(|_| watch.observe(plc.cnc_heartbeat())).collect();
    assert_eq!(verdicts.last(), Some(&PeerLiveness::Lost), "{verdicts:?}");
    assert!(!plc.cnc_process_alive());
    drop(plc);
    tests::remove_stale_segment(&instance);
}

#[test]
fn mismatching_layouts_are_refused_naming_both_values() {
    let instance = unique_instance("mismatch");
    let _segment = CncSegment::create(&instance, 1, 1).unwrap();
    let current = LayoutIdentity::current();

    let err = PlcSegment::attach_expecting(
        &instance,
        LayoutIdentity {
            version: 99,
            ..current
        },
    )
    .unwrap_err();
    assert_eq!(
        err,
        AttachError::VersionMismatch {
            cnc: current.version,
            plc: 99
        }
    );
    assert!(err
        .to_string()
        .contains(&format!("CNC has {}, PLC has 99", current.version)));

    let err = PlcSegment::attach_expecting(
        &instance,
        LayoutIdentity {
            hash: 0xDEAD,
            ..current
        },
    )
    .unwrap_err();
    assert_eq!(
        err,
        AttachError::LayoutMismatch {
            cnc: current.hash,
            plc: 0xDEAD
        }
    );

    let err = PlcSegment::attach_expecting(
        &instance,
        LayoutIdentity {
            size: 4096,
            ..current
        },
    )
    .unwrap_err();
    assert_eq!(
        err,
        AttachError::SizeMismatch {
            cnc: current.size,
            plc: 4096
        }
    );

    assert!(PlcSegment::attach(&instance).is_ok());
}

#[test]
fn missing_and_truncated_segments_are_typed_errors() {
    let create_raw =
        |name: &str, size| hli_transport::segment::create_raw_object(name, size).unwrap();
    let instance = unique_instance("trunc");
    assert!(matches!(
        PlcSegment::attach(&instance),
        Err(AttachError::NotFound { .. })
    ));
    assert!(matches!(
        PlcSegment::attach("bad/name"),
        Err(AttachError::InvalidName { .. })
    ));

    // Another program left a small object under the segment's name.
    let _small = create_raw(
        &hli_transport::segment::segment_name(&instance).unwrap(),
        64,
    );
    match PlcSegment::attach(&instance) {
        Err(AttachError::Truncated {
            found, expected, ..
        }) => {
            assert_eq!(found, 64);
            assert_eq!(expected, hli_transport::segment::IMAGE_SIZE as u64);
        }
        other => panic!("expected Truncated, got {other:?}"),
    }

    let instance = unique_instance("magic");
    let _junk = create_raw(
        &hli_transport::segment::segment_name(&instance).unwrap(),
        1 << 16,
    );
    assert!(matches!(
        PlcSegment::attach(&instance),
        Err(AttachError::BadMagic { cnc: 0, .. })
    ));
}

#[test]
fn segment_is_owner_only_and_removed_on_drop() {
    use std::os::unix::fs::PermissionsExt;
    let instance = unique_instance("perm");
    let segment = CncSegment::create(&instance, 1, 1).unwrap();
    let path = format!("/dev/shm/{}", segment.name());
    let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600);
    drop(segment);
    assert!(std::fs::metadata(&path).is_err());
    assert!(matches!(
        PlcSegment::attach(&instance),
        Err(AttachError::NotFound { .. })
    ));
}

#[test]
fn too_many_channels_or_axes_are_refused() {
    let instance = unique_instance("counts");
    assert!(matches!(
        CncSegment::create(&instance, 13, 1),
        Err(CreateError::TooMany {
            what: "channel",
            requested: 13,
            capacity: 12
        })
    ));
    assert!(matches!(
        CncSegment::create(&instance, 1, 33),
        Err(CreateError::TooMany { what: "axis", .. })
    ));
}

#[test]
fn a_new_plc_finds_every_plc_leaf_set_back_and_the_defaults_written() {
    use hli::desc::SymbolWriter;
    use hli::symbols::{SymbolKind, SymbolTable};
    let instance = unique_instance("reset-units");
    let segment = CncSegment::create(&instance, 2, 3).unwrap();
    let fresh = segment.memory().snapshot();
    // A PLC that wrote everywhere it may (and the CNC's own leaves, which stay).
    let plc_side = |w: SymbolWriter| matches!(w, SymbolWriter::Plc | SymbolWriter::Both);
    let leaves: Vec<_> = SymbolTable::global()
        .symbols()
        .iter()
        .filter(|s| matches!(s.kind, SymbolKind::Leaf(_)) && !s.path.starts_with("header."))
        .collect();
    for s in &leaves {
        for k in 0..s.size {
            segment.memory().place::<u8>(s.offset + k).store(0x5A);
        }
    }
    let cleared = segment.reset_plc_units();
    assert_eq!(
        cleared,
        leaves.iter().filter(|s| plc_side(s.writer)).count(),
        "every PLC-side leaf, whatever its size"
    );
    let after = segment.memory().snapshot();
    for s in &leaves {
        let range = s.offset..s.offset + s.size;
        if plc_side(s.writer) {
            // Cleared, or the default a fresh segment has (the path override's 100 %).
            assert_eq!(after[range.clone()], fresh[range], "{}", s.path);
        } else {
            assert!(after[range].iter().all(|b| *b == 0x5A), "{} kept", s.path);
        }
    }
}

#[test]
fn a_segment_of_another_user_is_refused_naming_its_owner() {
    // A well-formed segment whose file belongs to another user (uid 65534, "nobody").
    // Giving a file away takes root; elsewhere the test says so and checks nothing.
    let instance = unique_instance("foreign");
    let segment = CncSegment::create(&instance, 1, 1).unwrap();
    let path = format!("/dev/shm/{}", segment.name());
    if let Err(e) = std::os::unix::fs::chown(&path, Some(65534), None) {
        eprintln!("skipped: cannot give {path} to another user ({e}); needs root");
        return;
    }
    match PlcSegment::attach(&instance) {
        Err(AttachError::ForeignOwner { name, owner, .. }) => {
            assert_eq!(owner, 65534);
            assert_eq!(name, segment.name());
        }
        other => panic!("expected ForeignOwner, got {other:?}"),
    }
}

#[test]
fn every_file_the_shared_memory_layer_makes_is_owner_only() {
    // A CNC and a PLC with their segment, events and acyclic services; then every iceoryx2
    // file of this user (in /dev/shm and under /tmp/iceoryx2) and the segment are checked by
    // mode bits: no group or other bit on files, no write bit for others on directories.
    // iceoryx2's one per-domain node counter (`*.global_mgmt`, 16 bytes) is made world-writable
    // by iceoryx2 itself for all users of a domain; it holds no data of ours and is named
    // here as the exception (docs/reliability.md).
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let instance = unique_instance("modes");
    let cnc = CncSegment::create(&instance, 1, 1).unwrap();
    let _events =
        hli_transport::events::EventLink::open(&instance, hli_transport::events::Side::Cnc)
            .unwrap();
    let _server = hli_transport::rpc::AcyclicServer::open(&instance).unwrap();
    let _plc = PlcSegment::attach(&instance).unwrap();
    let _plc_events =
        hli_transport::events::EventLink::open(&instance, hli_transport::events::Side::Plc)
            .unwrap();
    let _client = hli_transport::rpc::AcyclicClient::open(&instance).unwrap();
    let me = std::fs::metadata("/proc/self").unwrap().uid();
    let mut files = vec![std::path::PathBuf::from(format!("/dev/shm/{}", cnc.name()))];
    let mut dirs = vec![std::path::PathBuf::from("/tmp/iceoryx2")];
    for entry in std::fs::read_dir("/dev/shm").unwrap().flatten() {
        if entry.file_name().to_string_lossy().starts_with("iox2_") {
            files.push(entry.path());
        }
    }
    let mut checked_dirs = 0;
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        checked_dirs += 1;
        for entry in entries.flatten() {
            match entry.file_type() {
                Ok(t) if t.is_dir() => dirs.push(entry.path()),
                Ok(_) => files.push(entry.path()),
                Err(_) => {}
            }
        }
        // Files of other tests come and go meanwhile: a vanished one is skipped.
        let Ok(meta) = std::fs::metadata(&dir) else {
            continue;
        };
        if meta.uid() == me {
            let mode = meta.permissions().mode() & 0o777;
            assert_eq!(
                mode & 0o002,
                0,
                "{} is writable by others: {mode:o}",
                dir.display()
            );
        }
    }
    let mut checked = 0;
    for file in files {
        let Ok(meta) = std::fs::metadata(&file) else {
            continue;
        };
        let name = file.to_string_lossy();
        if meta.uid() != me || name.ends_with(".global_mgmt") {
            continue;
        }
        let mode = meta.permissions().mode() & 0o777;
        assert_eq!(mode & 0o077, 0, "{name} is open to others: {mode:o}");
        checked += 1;
    }
    assert!(
        checked >= 5 && checked_dirs >= 2,
        "{checked} files, {checked_dirs} dirs"
    );
}
