//! The cyclic operations of the HLI (handshakes, heartbeats, views) allocate nothing.

use hli::image::heap_image;
use hli::views::{CncView, PlcView};

use crate::counting_alloc;
use counting_alloc::allocations;

#[test]
fn handshake_cycle_does_not_allocate() {
    let mem = heap_image(2, 4);
    let cnc = CncView::new(&mem);
    let plc = PlcView::new(&mem);
    let tx = plc.dyn_cs_command(1).unwrap();
    let mut rx = cnc.dyn_cs_command(1).unwrap();
    let req_tx = cnc.dyn_cs_request(1).unwrap();
    let mut req_rx = plc.dyn_cs_request(1).unwrap();
    let mut payload: hli::layout::HliCoordinateSystemInt = bytemuck::Zeroable::zeroed();

    let before = allocations();
    for i in 0..10_000 {
        payload.translation[0] = i;
        tx.try_send(&payload).unwrap();
        let got = rx.try_take().unwrap().unwrap();
        req_tx.try_send(&got).unwrap();
        let back = req_rx.try_take().unwrap().unwrap();
        assert_eq!(back.translation[0], i);
        let _ = cnc.set_dyn_cs_state(1, hli::enums::DynCsState::Active);
        let _ = plc.dyn_cs_state(1).unwrap().unwrap();
        let _ = plc.axis_state(3).unwrap();
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations in the handshake cycle");
}
