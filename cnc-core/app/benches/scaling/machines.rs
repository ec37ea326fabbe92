//! The machines of the scaling bench, one builder per dimension: each returns the machine
//! running (warmed up, every slave coupled, the FIFO streaming) behind [`Tick`].

use cnc_app::scenario::fleet::running;
use cnc_app::scenario::InProcess;
use cnc_core::axis::config::AxisConfig;
use cnc_core::cam::machine::CamEngine;
use cnc_core::cam::online::CamStore;
use cnc_core::cam::{CamProfile, PositionTable, TableType};
use cnc_core::fifo::machine::FifoEngine;
use cnc_core::fifo::{FifoParams, OverrideType};
use cnc_core::machine::{Engine, Machine, MachineSetup};
use cnc_core::saw::machine::SawEngine;
use hli::calls::axis::AxisCommandCall;
use hli::calls::cam::{CamInCall, CamInterpolation, CamTableSelectCall};
use hli::calls::fifo::{rows_header, FifoIntegrateCall, FifoReply, FifoStartCall};
use hli::calls::saw::{SawGearInCall, SawSyncTarget};
use hli::calls::AcyclicCall;
use hli::enums::AxisState;
use hli::views::{CncView, PlcView};
use hli::ImageMemory;

const TICK: f64 = 0.001;
const FIFO_AXES: usize = 6;

/// Something that ticks; `upkeep` runs untimed between batches of `Tick::batch` ticks.
pub trait Ticking {
    fn tick(&mut self);
    fn upkeep(&mut self) {}
}

/// A running machine and how many ticks it takes between two upkeeps.
pub struct Tick {
    pub batch: usize,
    pub run: Box<dyn Ticking>,
}

struct Plain {
    machine: Machine,
    memory: ImageMemory,
}

impl Ticking for Plain {
    fn tick(&mut self) {
        self.machine.tick(&self.memory);
    }
}

struct Fleet(InProcess);

impl Ticking for Fleet {
    fn tick(&mut self) {
        self.0.machine.tick(&self.0.memory);
    }
}

fn plain(machine: Machine, memory: ImageMemory) -> Tick {
    Tick {
        batch: usize::MAX,
        run: Box::new(Plain { machine, memory }),
    }
}

fn call<C: AcyclicCall>(
    machine: &mut Machine,
    memory: &ImageMemory,
    target: u32,
    body: &C,
) -> C::Reply {
    machine
        .call(&CncView::new(memory), target, body)
        .expect("answered")
}

/// A linear axis without software limits (the benches run for minutes).
fn free_axis(name: &str, id: u32) -> AxisConfig {
    let mut c = AxisConfig::linear(name, id);
    c.soft_limits = None;
    c
}

/// A machine of `axes` (all switched on) and `engines`, ticked once.
fn machine(axes: Vec<AxisConfig>, engines: Vec<Box<dyn Engine>>) -> (Machine, ImageMemory) {
    let n = axes.len();
    let mut machine = Machine::new(MachineSetup {
        channels: Vec::new(),
        axes,
        engines,
        cycle_s: TICK,
    })
    .expect("machine");
    let memory = hli::image::heap_image(0, n as u32);
    for i in 0..n {
        let axis = machine.axes_mut().axis_mut(i).expect("axis");
        axis.switch_on().expect("power");
    }
    machine.tick(&memory);
    (machine, memory)
}

fn warm(machine: &mut Machine, memory: &ImageMemory, ticks: usize) {
    for _ in 0..ticks {
        machine.tick(memory);
    }
}

/// `n` tracking robots with their programs (the `channels` bench's fleet).
pub fn channels(n: usize) -> Tick {
    Tick {
        batch: usize::MAX,
        run: Box::new(Fleet(running(n, 2_000).expect("fleet running"))),
    }
}

/// `n` single axes, every one moving at 1 unit/s (half of them backwards).
pub fn axes(n: usize) -> Tick {
    let configs = (0..n)
        .map(|i| free_axis(&format!("A{i}"), i as u32 + 1))
        .collect();
    let (mut m, memory) = machine(configs, Vec::new());
    for i in 0..n {
        let dir = if i % 2 == 0 { 1 } else { -1 };
        let go = AxisCommandCall::move_velocity(dir, [1.0, 100.0, 100.0, 1000.0]);
        call(&mut m, &memory, i as u32, &go);
    }
    warm(&mut m, &memory, 200);
    plain(m, memory)
}

/// A position table of `rows` rows, one master unit each, a slave wave from 0 to 0.
fn table(rows: usize) -> CamProfile {
    let r: Vec<[f64; 2]> = (0..rows)
        .map(|i| {
            let phase = i as f64 / (rows - 1) as f64 * std::f64::consts::TAU;
            [i as f64, 5.0 * phase.sin()]
        })
        .collect();
    let t = PositionTable::new(&r, TableType::Equidistant, CamInterpolation::Linear, true);
    CamProfile::Table(t.expect("bench table"))
}

/// A conveyor at 360 units/s and `slaves` cam slaves, each on its own table of `rows` rows.
fn cams(slaves: usize, rows: usize) -> Tick {
    // One table per slave (slave s on table s), each selected for its own coupling.
    let mut store = CamStore::new();
    for id in 1..=slaves as u32 {
        store.insert(id, table(rows)).expect("table");
    }
    let mut axes = vec![AxisConfig::rotary("Conveyor", 1)];
    axes.extend((0..slaves).map(|i| free_axis(&format!("S{i}"), i as u32 + 2)));
    let (mut m, memory) = machine(axes, vec![Box::new(CamEngine::new(store, slaves + 1))]);
    for s in 1..=slaves as u32 {
        let select = CamTableSelectCall {
            periodic: 1,
            master_absolute: 1,
            slave_absolute: 1,
            reserved: 0,
        };
        assert_eq!(call(&mut m, &memory, s, &select).error_id, 0);
        let cam_in = CamInCall {
            master: 0,
            table_id: s,
            start_mode: 1,
            master_scaling: 1.0,
            slave_scaling: 1.0,
            ..CamInCall::default()
        };
        assert_eq!(call(&mut m, &memory, s, &cam_in).error_id, 0);
    }
    let run = AxisCommandCall::move_velocity(1, [360.0, 3600.0, 3600.0, 36000.0]);
    call(&mut m, &memory, 0, &run);
    warm(&mut m, &memory, 1_000);
    for s in 1..=slaves {
        let slave = m.axes().axis(s).expect("slave");
        assert!(
            slave.coupling().is_some() && slave.error().is_none(),
            "slave {s} coupled"
        );
    }
    plain(m, memory)
}

/// `n` cam slaves on 1,000-row tables.
pub fn cam_slaves(n: usize) -> Tick {
    cams(n, 1_000)
}

/// One cam slave on a table of `rows` rows.
pub fn cam_table(rows: usize) -> Tick {
    cams(1, rows)
}

/// A running 6-axis FIFO group (T_f = 1 tick) whose queue is kept at `depth` rows.
struct Fifo {
    machine: Machine,
    memory: ImageMemory,
    depth: usize,
    next: usize,
}

impl Fifo {
    fn queued(&self) -> usize {
        let group = PlcView::new(&self.memory).fifo_group(0).expect("group 0");
        self.depth.max(2) - group.free_r as usize
    }

    fn refill(&mut self, rows: usize) {
        let t = |k: usize| k as f64 * TICK;
        let values: Vec<f64> = (self.next..self.next + rows)
            .flat_map(|k| {
                (0..FIFO_AXES).map(move |c| (c + 1) as f64 * (t(k) * (0.3 + 0.1 * c as f64)).sin())
            })
            .collect();
        let header = rows_header(0, FIFO_AXES as u32, rows as u32, false);
        let (body, len) = self
            .machine
            .dispatch_bulk(&header, &values)
            .expect("rows taken");
        let reply: FifoReply = bytemuck::pod_read_unaligned(&body[..len as usize]);
        assert_eq!(reply.error_id, 0, "rows refused");
        self.next += rows;
    }
}

impl Ticking for Fifo {
    fn tick(&mut self) {
        self.machine.tick(&self.memory);
    }

    fn upkeep(&mut self) {
        let group = PlcView::new(&self.memory).fifo_group(0).expect("group 0");
        assert_eq!(
            group.flags_r & hli::layout::FIFO_FLAG_UNDERRUN,
            0,
            "ran dry"
        );
        let missing = self.depth - self.queued();
        if missing > 0 {
            self.refill(missing);
        }
    }
}

/// A 6-axis FIFO group streaming, `depth` rows queued at every batch's start.
pub fn fifo_depth(depth: usize) -> Tick {
    let axes = (0..FIFO_AXES)
        .map(|i| free_axis(&format!("F{i}"), i as u32 + 1))
        .collect();
    let params = FifoParams::new(
        FIFO_AXES,
        depth.max(2),
        TICK,
        OverrideType::Pt2 { t0_s: 0.02 },
    );
    let engine = FifoEngine::new(&[params.expect("fifo params")], TICK).expect("fifo engine");
    let (mut machine, memory) = machine(axes, vec![Box::new(engine)]);
    for axis in 0..FIFO_AXES as u32 {
        let integrate = FifoIntegrateCall {
            axis,
            group_position: axis + 1,
        };
        let reply: FifoReply = call(&mut machine, &memory, 0, &integrate);
        assert_eq!(reply.error_id, 0);
    }
    let mut run = Fifo {
        machine,
        memory,
        depth,
        next: 0,
    };
    run.refill(depth);
    let reply: FifoReply = call(&mut run.machine, &run.memory, 0, &FifoStartCall::default());
    assert_eq!(reply.error_id, 0);
    // Half the queue per batch at most (one row a tick), then topped up again.
    Tick {
        batch: (depth / 2).clamp(1, 1_000),
        run: Box::new(run),
    }
}

/// A master at 100 units/s and `n` flying-saw slaves geared in at ratio 1, synchronous.
pub fn saw(n: usize) -> Tick {
    let axes = (0..=n)
        .map(|i| free_axis(&format!("A{i}"), i as u32 + 1))
        .collect();
    let (mut m, memory) = machine(axes, vec![Box::new(SawEngine::new(n + 1, TICK))]);
    let go = AxisCommandCall::move_velocity(1, [100.0, 1000.0, 1000.0, 1e5]);
    call(&mut m, &memory, 0, &go);
    warm(&mut m, &memory, 300);
    for s in 1..=n as u32 {
        let gear_in = SawGearInCall {
            master: 0,
            target: SawSyncTarget::Velocity.raw(),
            ratio_numerator: 1.0,
            ratio_denominator: 1,
            ..SawGearInCall::default()
        };
        assert_eq!(call(&mut m, &memory, s, &gear_in).error_id, 0);
    }
    warm(&mut m, &memory, 3_000);
    for s in 1..=n {
        let state = PlcView::new(&memory)
            .axis_state(s)
            .expect("axis")
            .axis_state_r;
        assert_eq!(
            state,
            AxisState::SlaveSynchronous.raw(),
            "saw slave {s} synchronous"
        );
    }
    plain(m, memory)
}
