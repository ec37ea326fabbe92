//! The run loop and its waits: the interpreter runs blocks until one moves or waits (at most
//! [`BLOCKS_PER_TICK`] a tick), each block decoded when the channel reaches it with the
//! variables of that moment; a wait (M function, `#WAIT SYN`, tracking, independent axes,
//! dwell) holds the next block back until it is over.

use super::*;

/// The program and where the channel is in it.
pub(super) struct ProgramRun {
    pub(super) program: Option<LoadedProgram>,
    pub(super) decoder: DecoderState,
    /// Follows the program's control flow and calls.
    pub(super) interp: Interpreter,
    /// Source line of the block executing.
    pub(super) line: u32,
    /// The elements of the block decoded last, and the next one to carry out.
    pub(super) pending: Vec<Decoded>,
    pub(super) pending_at: usize,
    pub(super) wait: Option<Wait>,
    pub(super) wait_ids: SyncIds,
    /// NC blocks the interpreter handed on (each block once, loops counted per pass).
    pub(super) blocks_executed: u64,
    /// Found while decoding ahead of a contour: the program's end, or an error with its
    /// line; acted on once the contour has come to rest.
    pub(super) end_deferred: bool,
    pub(super) fault_deferred: Option<(u32, ChannelFault)>,
    /// Line of the block decoded last (the line shown is the contour's while one runs).
    pub(super) decoded_line: u32,
}

impl ProgramRun {
    /// No program yet, for a channel with these axes.
    pub(super) fn new(axes: &[String]) -> Self {
        Self {
            program: None,
            decoder: DecoderState::new(axes),
            interp: Interpreter::new(),
            line: 0,
            pending: Vec::with_capacity(16),
            pending_at: 0,
            wait: None,
            wait_ids: SyncIds::default(),
            blocks_executed: 0,
            end_deferred: false,
            fault_deferred: None,
            decoded_line: 0,
        }
    }
}

/// What the interpreter waits for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Wait {
    /// The PLC's acknowledge of M function `code` announced with `id`.
    MFunction { code: u32, id: u32 },
    /// The announcement of `code` could not be posted yet (the previous one is unread).
    MAnnounce { code: u32 },
    /// `#WAIT SYN` for the ids in `wait_ids`, since tick `since`, when the board had counted
    /// `aborts` aborted channels.
    Sync { since: u64, aborts: u32 },
    /// `#TRACK CS ... WAIT`.
    Tracking,
    /// `#WAIT INDP ALL` or an `INDP_SYN` move.
    Independent,
    /// `G04` / `#TIME`: until the channel's tick counter reaches this.
    Dwell { until: u64 },
}

/// The variables a block sees when it is decoded.
struct ChannelVars {
    track_cs: [f64; 6],
}

impl Vars for ChannelVars {
    fn get(&self, name: &str) -> Option<f64> {
        KNOWN_VARIABLES
            .iter()
            .position(|v| *v == name)
            .map(|i| self.track_cs[i])
    }
}

/// The file name of a program's name (a path when it was loaded from a file).
fn program_file_name(name: &str) -> &str {
    std::path::Path::new(name)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(name)
}

impl Channel {
    /// Loads `program` and starts it (a checked program; see [`LoadedProgram::load`]).
    /// A channel that failed is reset first (see [`Channel::reset`]): it starts again from
    /// where its axes came to rest, and is refused while they still move or track.
    pub fn start(&mut self, program: LoadedProgram) -> Result<(), ResetError> {
        if self.state == RunState::Error {
            self.reset()?;
        }
        self.control.program_name = hli::layout::nul_padded(program_file_name(&program.name));
        self.control.start = None;
        self.run.program = Some(program);
        self.begin_selected();
        Ok(())
    }

    /// Selects `program` without starting it (the PLC starts it with START).
    pub fn select(&mut self, program: LoadedProgram) {
        self.control.program_name = hli::layout::nul_padded(program_file_name(&program.name));
        self.control.start = None;
        self.control.fresh = true;
        self.run.program = Some(program);
    }

    /// Starts the selected program (allocates: between ticks only).
    pub(super) fn begin_selected(&mut self) {
        let Some(program) = self.run.program.as_ref() else {
            return;
        };
        // A new program starts from the modal defaults the check assumed (G90 G17 G71 G53 D0,
        // no feed), where the axes stand.
        self.run.decoder = DecoderState::new(&self.config.axes);
        for (i, p) in self.motion.programmed.iter().enumerate() {
            self.run.decoder.set_position(i, *p);
        }
        self.run.decoder.configure(&program.setup);
        self.run.interp.start(&program.set);
        if let Some(start) = self.control.start.as_deref() {
            // A block search's start: its modal state and flow, where the axes stand.
            self.run.decoder = start.decoder.clone();
            self.run.interp = start.interp.clone();
            for (i, p) in self.motion.programmed.iter().enumerate() {
                self.run.decoder.set_position(i, *p);
            }
        }
        self.run.pending.clear();
        self.run.pending_at = 0;
        self.run.end_deferred = false;
        self.run.fault_deferred = None;
        self.state = RunState::Running;
        self.run.wait = None;
        self.error = None;
        let c = &mut self.control;
        (c.program_ended, c.block_ran, c.block_stop, c.held) = (false, false, false, false);
        c.fresh = false;
        if self.config.provide_channel_interface.track_cs {
            self.pose.interface_on = true;
        }
        self.pose.tracker.restart();
    }

    /// Line of the block executing.
    pub fn line(&self) -> u32 {
        self.run.line
    }

    /// NC blocks run so far (a block in a loop counts once per pass).
    pub fn blocks_executed(&self) -> u64 {
        self.run.blocks_executed
    }

    /// `f_wait` of a PLC transition, the counterpart of the NC command's WAIT: the program
    /// goes on to its next block only once the switching has finished (ACTIVE or INACTIVE).
    /// The block under way runs on; nothing waits when no program runs.
    pub(super) fn hold_program_until_settled(&mut self) {
        if self.state == RunState::Running && self.run.wait.is_none() {
            self.run.wait = Some(Wait::Tracking);
        }
    }

    /// Runs blocks until one moves or waits.
    pub(super) fn interpret(
        &mut self,
        masters: &[Option<MasterSample>; MAX_CHANNELS],
        sync: &mut SyncBoard,
    ) {
        let mut joined = 0;
        for _ in 0..BLOCKS_PER_TICK {
            if let Some(wait) = self.run.wait {
                if !self.wait_done(wait, sync) {
                    return;
                }
                self.run.wait = None;
            }
            if self.motion.path.is_some() || self.state != RunState::Running {
                return;
            }
            if !self.contour_may_look_ahead() {
                return;
            }
            // Feed hold and a single-block stop: waits end as they would, nothing new starts.
            if self.control.held || self.control.block_stop {
                return;
            }
            if self.run.pending_at < self.run.pending.len() && self.motion.contour.active() {
                // Look-ahead: a straight block joins the contour; anything else waits until
                // the contour has come to rest.
                if self.pose.trafo && joined >= joint_caps::TRAFO_BLOCKS_PER_TICK {
                    return;
                }
                joined += 1;
                if !self.join_pending() {
                    self.motion.contour.close();
                    return;
                }
                continue;
            }
            if self.run.pending_at < self.run.pending.len() {
                let element = core::mem::replace(
                    &mut self.run.pending[self.run.pending_at],
                    Decoded::Flush {
                        line: 0,
                        wait: false,
                    },
                );
                self.run.pending_at += 1;
                self.execute(element, masters, sync);
                continue;
            }
            self.run.pending.clear();
            self.run.pending_at = 0;
            if self.control.single_block && self.control.block_ran {
                // Single block: the block is done; START runs the next one.
                self.control.block_stop = true;
                return;
            }
            if !self.next_block_decoded() {
                return;
            }
        }
    }

    /// With a contour under way: whether the interpreter may decode and join more blocks
    /// (its window is open and has room). When the contour has come to rest, what decoding
    /// ahead found takes effect: the program's end, or its error.
    fn contour_may_look_ahead(&mut self) -> bool {
        if self.motion.contour.active() {
            if let Some(line) = self.motion.contour.line() {
                self.run.line = line;
            }
            if self.control.single_block {
                // Switched on during a contour: no block joins it any more.
                self.motion.contour.close();
            }
            return !self.motion.contour.closed() && self.motion.contour.has_room();
        }
        self.run.line = self.run.decoded_line;
        if let Some((line, fault)) = self.run.fault_deferred.take() {
            self.run.line = line;
            self.fail(fault);
            return false;
        }
        if core::mem::take(&mut self.run.end_deferred) {
            self.program_end();
            return false;
        }
        true
    }

    /// The next pending element joins the contour, when it is a straight block.
    fn join_pending(&mut self) -> bool {
        let Some(Decoded::Motion(m)) = self.run.pending.get(self.run.pending_at) else {
            return false;
        };
        let m = m.clone();
        if !self.join_contour(&m) {
            return false;
        }
        self.run.pending_at += 1;
        true
    }

    /// Runs the interpreter one step (a block decoded into `pending`, or a `$` statement
    /// followed); `false` when the program ended or failed.
    pub(super) fn next_block_decoded(&mut self) -> bool {
        let Some(program) = self.run.program.as_ref() else {
            self.state = RunState::Finished;
            return false;
        };
        let vars = ChannelVars {
            track_cs: self.pose.tracker.zero_values(),
        };
        match self.run.interp.step(
            &program.set,
            &mut self.run.decoder,
            &vars,
            &mut self.run.pending,
        ) {
            Ok(Step::End) if self.motion.contour.active() => {
                self.motion.contour.close();
                self.run.end_deferred = true;
                false
            }
            Ok(Step::End) => {
                self.program_end();
                false
            }
            Ok(Step::Block { unit, block }) => {
                self.run.blocks_executed += 1;
                self.control.block_ran = true;
                if let Some(b) = program
                    .set
                    .units
                    .get(unit as usize)
                    .and_then(|u| u.tree.blocks.get(block as usize))
                {
                    self.run.line = b.line;
                    self.run.decoded_line = b.line;
                }
                true
            }
            // The channel's values are a running machine's: nothing is undecided here.
            Ok(Step::Control | Step::Undecided) => true,
            Err(e) => {
                // The failing block's line (not the last one that ran): the block whose span
                // holds the error's, found by bisection (nothing allocated).
                if let Some(unit) = program.set.units.get(e.unit as usize) {
                    let blocks = &unit.tree.blocks;
                    let after = blocks.partition_point(|b| b.span.start <= e.span.start);
                    if let Some(b) = after.checked_sub(1).and_then(|i| blocks.get(i)) {
                        self.run.line = b.line;
                    }
                }
                let fault = ChannelFault::Program(e.fault);
                if self.motion.contour.active() {
                    // Decoded ahead: the contour runs to the end of what it holds first.
                    self.run.fault_deferred = Some((self.run.line, fault));
                    self.run.line = self.run.decoded_line;
                    self.motion.contour.close();
                } else {
                    self.fail(fault);
                }
                false
            }
        }
    }

    /// A feed hold does not count against `sync_timeout_s`: the wait's clock stands.
    pub(super) fn hold_sync_clock(&mut self) {
        if let (true, Some(Wait::Sync { since, .. })) = (self.control.held, self.run.wait.as_mut())
        {
            *since += 1;
        }
    }

    /// `#WAIT SYN`: done when every id holds a signal; fails when no other channel runs any
    /// more after one was stopped, reset or failed, or after the channel's `sync_timeout_s`.
    fn sync_done(&mut self, sync: &mut SyncBoard, since: u64, aborts: u32) -> bool {
        if sync.try_wait(self.run.wait_ids.as_slice()) {
            return true;
        }
        if sync.aborts() != aborts && !sync.others_running(self.index) {
            self.fail(ChannelFault::SyncPartnerStopped);
        } else if let Some(limit) = self.config.sync_timeout_s {
            let waited = (self.tick - since) as f64 * self.cycle_s;
            if waited >= limit {
                self.fail(ChannelFault::SyncTimeout(limit));
            }
        }
        false
    }

    pub(super) fn wait_done(&mut self, wait: Wait, sync: &mut SyncBoard) -> bool {
        match wait {
            Wait::MFunction { code, id } => {
                if !self.plc.inputs.has_m_unit {
                    return true;
                }
                match self.plc.inputs.m_ack.take() {
                    Some(HliMFunctionAck { m_code, request_id }) => {
                        // A stale acknowledge (other id) is consumed and ignored.
                        let done = request_id == id && m_code == code as i32;
                        self.plc.m_functions_acked += u64::from(done);
                        done
                    }
                    None => false,
                }
            }
            Wait::MAnnounce { code } => {
                if self.announce(code) {
                    self.run.wait = Some(Wait::MFunction {
                        code,
                        id: self.plc.m_next_id,
                    });
                }
                false
            }
            Wait::Sync { since, aborts } => self.sync_done(sync, since, aborts),
            Wait::Tracking => self.pose.tracker.settled(),
            Wait::Independent => self.motion.independent.iter().all(|(_, active)| !*active),
            Wait::Dwell { until } => self.tick >= until,
        }
    }
}
