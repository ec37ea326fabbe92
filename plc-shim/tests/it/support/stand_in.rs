//! A stand-in CNC for the PLC's tests: a heap image and both ends of the acyclic service, on
//! an instance of the test's own. Nothing answers a call unless the test polls the server.

use hli::views::PlcView;
use hli_transport::rpc::{AcyclicClient, AcyclicServer};
use plc_shim::runtime::{Link, PlcIo, PlcProgram};

pub struct StandIn {
    pub memory: hli::ImageMemory,
    #[allow(dead_code)]
    pub server: AcyclicServer,
    pub client: AcyclicClient,
    pub cycle: u64,
}

impl StandIn {
    /// A stand-in with one channel and `axes` axes, on an instance named after `case`.
    pub fn new(case: &str, axes: u32) -> StandIn {
        let instance = tests::unique_instance(case);
        StandIn {
            memory: hli::image::heap_image(1, axes),
            server: AcyclicServer::open(&instance).unwrap(),
            client: AcyclicClient::open(&instance).unwrap(),
            cycle: 0,
        }
    }

    /// One PLC cycle of `program`, which must not halt in it.
    pub fn cycle(&mut self, program: &mut dyn PlcProgram) {
        self.cycle += 1;
        let mut io = PlcIo {
            view: PlcView::new(&self.memory),
            memory: &self.memory,
            acyclic: &mut self.client,
            cycle: self.cycle,
            link: Link::Operational,
        };
        program.cycle(&mut io);
        assert!(!program.halted(), "{}", program.summary());
    }
}
