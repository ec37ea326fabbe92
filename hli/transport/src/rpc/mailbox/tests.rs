//! The mailbox's slots through their states, by hand.

use super::*;

fn name(case: &str) -> String {
    format!("mbx-{case}-{}", std::process::id())
}

fn request(id: u32) -> AcyclicRequest {
    AcyclicRequest {
        invoke_id: id,
        kind: 7,
        target: 3,
        body_len: 4,
        body: [id as u8; hli::wire::ACYCLIC_BODY_SIZE],
    }
}

fn echo(r: &AcyclicRequest) -> AcyclicResponse {
    AcyclicResponse {
        invoke_id: r.invoke_id,
        kind: r.kind,
        error_code: 0,
        body_len: r.body_len,
        body: r.body,
    }
}

fn state(m: &Mailbox, i: usize) -> u32 {
    m.slot(i).state().load(SeqCst)
}

#[test]
fn a_call_goes_out_is_answered_and_taken_once() {
    let server = Mailbox::create(&name("round")).unwrap();
    let client = Mailbox::open(&name("round")).unwrap();
    let mut ages = [0; MAILBOX_SLOTS];
    let (slot, ticket) = client.send(&request(9)).unwrap();
    assert_eq!(
        client.take(slot, ticket).map(|r| r.invoke_id),
        None,
        "not yet"
    );
    assert_eq!(server.serve(&mut ages, echo), 1);
    assert_eq!(
        client.take(slot, ticket + 1).map(|r| r.invoke_id),
        None,
        "not ours"
    );
    let reply = client.take(slot, ticket).unwrap();
    assert_eq!((reply.invoke_id, reply.body[0]), (9, 9));
    assert_eq!(
        client.take(slot, ticket).map(|r| r.invoke_id),
        None,
        "taken once"
    );
    assert_eq!(state(&server, slot), FREE);
    assert_eq!(server.serve(&mut ages, echo), 0);
}

#[test]
fn a_call_given_up_still_runs_and_its_slot_comes_free() {
    let server = Mailbox::create(&name("abandon")).unwrap();
    let client = Mailbox::open(&name("abandon")).unwrap();
    let mut ages = [0; MAILBOX_SLOTS];
    // Given up before the CNC saw it: answered, then freed by the server.
    let (slot, ticket) = client.send(&request(1)).unwrap();
    client.abandon(slot, ticket);
    let mut ran = 0;
    server.serve(&mut ages, |r| {
        ran += 1;
        echo(r)
    });
    assert_eq!((ran, state(&server, slot)), (1, FREE));
    // Given up after the reply came: freed at once.
    let (slot, ticket) = client.send(&request(2)).unwrap();
    server.serve(&mut ages, echo);
    assert_eq!(state(&server, slot), REPLY);
    client.abandon(slot, ticket);
    assert_eq!(state(&server, slot), FREE);
    // A stale ticket touches nothing: the slot is someone else's now.
    let (again, new) = client.send(&request(3)).unwrap();
    assert_eq!(again, slot);
    client.abandon(slot, ticket);
    assert_eq!((state(&server, slot), new != ticket), (REQUEST, true));
}

#[test]
fn the_slots_run_out_and_a_dead_clients_slots_come_back() {
    let server = Mailbox::create(&name("full")).unwrap();
    let client = Mailbox::open(&name("full")).unwrap();
    let mut ages = [0; MAILBOX_SLOTS];
    for id in 0..MAILBOX_SLOTS as u32 {
        client.send(&request(id)).unwrap();
    }
    let full = client.send(&request(99)).unwrap_err();
    assert_eq!(full, CallError::SlotsTaken);
    // Answered and never taken: kept while the claimant lives (this process)...
    assert_eq!(server.serve(&mut ages, echo), MAILBOX_SLOTS);
    for _ in 0..2 * STALE_POLLS {
        server.serve(&mut ages, echo);
    }
    assert_eq!(
        client.send(&request(99)).unwrap_err(),
        CallError::SlotsTaken
    );
    // ... freed after STALE_POLLS polls once it is gone (the answering poll counts), not before.
    for i in 0..MAILBOX_SLOTS {
        server.slot(i).pid().store(u32::MAX); // no such process
    }
    ages = [0; MAILBOX_SLOTS];
    for _ in 0..STALE_POLLS {
        server.serve(&mut ages, echo);
    }
    assert!(client.send(&request(99)).is_err());
    server.serve(&mut ages, echo);
    assert!(client.send(&request(99)).is_ok());
}

/// Two clients in threads of their own send and take calls against a server answering in a
/// third, all at once: every reply is the answer to its own request.
#[test]
fn clients_racing_for_slots_each_get_their_own_replies() {
    let server = Mailbox::create(&name("race")).unwrap();
    let done = std::sync::atomic::AtomicU32::new(0);
    std::thread::scope(|scope| {
        for t in 0..2u32 {
            let done = &done;
            scope.spawn(move || {
                let client = Mailbox::open(&name("race")).unwrap();
                for k in 0..2000u32 {
                    let id = t * 100_000 + k;
                    let (slot, ticket) = loop {
                        match client.send(&request(id)) {
                            Ok(sent) => break sent,
                            Err(_) => std::thread::yield_now(),
                        }
                    };
                    // A watchdog of iterations, not of time.
                    let reply = (0..10_000_000)
                        .find_map(|_| {
                            let r = client.take(slot, ticket);
                            if r.is_none() {
                                std::thread::yield_now();
                            }
                            r
                        })
                        .expect("watchdog: no reply");
                    assert_eq!((reply.invoke_id, reply.body[0]), (id, id as u8));
                }
                done.fetch_add(1, SeqCst);
            });
        }
        let mut ages = [0; MAILBOX_SLOTS];
        for _ in 0..100_000_000u64 {
            if done.load(SeqCst) == 2 {
                break;
            }
            server.serve(&mut ages, echo);
        }
        assert_eq!(done.load(SeqCst), 2, "watchdog: the clients did not finish");
    });
}

#[test]
fn a_mailbox_is_made_once_and_needs_its_server() {
    assert!(
        Mailbox::open(&name("none")).is_err(),
        "no server, no mailbox"
    );
    let server = Mailbox::create(&name("once")).unwrap();
    let second = Mailbox::create(&name("once")).unwrap_err();
    assert!(second.to_string().contains("live process"), "{second}");
    drop(server);
    assert!(
        Mailbox::open(&name("once")).is_err(),
        "removed with its server"
    );
    assert!(Mailbox::create(&name("once")).is_ok());
}

#[test]
fn calls_are_answered_in_the_order_they_were_sent() {
    let server = Mailbox::create(&name("order")).unwrap();
    let client = Mailbox::open(&name("order")).unwrap();
    let mut ages = [0; MAILBOX_SLOTS];
    // Slots 0 and 1 taken, 0 freed again: the third call takes slot 0, after the second.
    let (first, t1) = client.send(&request(1)).unwrap();
    client.send(&request(2)).unwrap();
    server.serve(&mut ages, echo);
    client.take(first, t1).unwrap();
    let (second_slot, _) = client.send(&request(3)).unwrap();
    client.send(&request(4)).unwrap();
    assert_eq!(second_slot, first, "the free slot 0 again");
    let mut order = Vec::new();
    server.serve(&mut ages, |r| {
        order.push(r.invoke_id);
        echo(r)
    });
    assert_eq!(order, [3, 4]);
}

fn bulk_refused() -> AcyclicResponse {
    AcyclicResponse {
        invoke_id: 0,
        kind: 0,
        error_code: 99,
        body_len: 0,
        body: [0; hli::wire::ACYCLIC_BODY_SIZE],
    }
}

fn header(rows: u32, columns: u32) -> BulkHeader {
    BulkHeader {
        kind: 50,
        target: 0,
        columns,
        rows,
    }
}

#[test]
fn a_bulk_block_is_written_in_place_and_arrives_whole_or_not_at_all() {
    let server = Mailbox::create(&name("bulk")).unwrap();
    let client = Arc::new(Mailbox::open(&name("bulk")).unwrap());
    let (mut ages, mut buffer) = ([0; BULK_SLOTS], Vec::with_capacity(BULK_MAX_VALUES));
    let mut got = Vec::new();
    let mut serve = |got: &mut Vec<(u32, Vec<f64>)>| {
        server.serve_bulk(&mut ages, &mut buffer, bulk_refused(), |h, v| {
            got.push((h.rows, v.to_vec()));
            AcyclicResponse {
                error_code: 0,
                ..bulk_refused()
            }
        })
    };
    // Written in two parts, sent whole, answered.
    let mut loan = client.loan(header(2, 3), 6, true).unwrap();
    loan.write(0, &[1.0, 2.0, 3.0]);
    loan.write(3, &[4.0, 5.0, 6.0, 7.0]); // the 7th is beyond the loan
    let ticket = loan.send().unwrap();
    assert_eq!(serve(&mut got), 1);
    assert_eq!(got, [(2, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0])]);
    assert_eq!(ticket.take().unwrap().error_code, 0);
    // A loan dropped unsent never arrives, and its slot comes free at once.
    let unsent = client.loan(header(1, 1), 1, true).unwrap();
    let slot = unsent.slot;
    drop(unsent);
    assert_eq!((serve(&mut got), state(&server, slot)), (0, FREE));
    // A count that is not rows x columns is refused before the handler sees it.
    let wrong = client.loan(header(2, 2), 3, true).unwrap().send().unwrap();
    assert_eq!(serve(&mut got), 1);
    assert_eq!((got.len(), wrong.take().unwrap().error_code), (1, 99));
    // More numbers than a slot holds are refused at the loan.
    assert_eq!(
        client
            .loan(header(1, 1), BULK_MAX_VALUES + 1, false)
            .unwrap_err(),
        CallError::TooLarge(BULK_MAX_VALUES + 1)
    );
    // The bulk slots run out apart from the call slots.
    let loans: Vec<BulkLoan> = (0..BULK_SLOTS)
        .map(|_| client.loan(header(1, 1), 1, true).unwrap())
        .collect();
    assert!(client.loan(header(1, 1), 1, true).is_err());
    assert!(client.send(&request(1)).is_ok());
    drop(loans);
}
