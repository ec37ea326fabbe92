//! The enumerations of the channel control unit (`gpCh[i]^channel_control`): commands, states,
//! modes, the answer of a command, refusals and operator signals.

hli_enum! {
    /// A command of the PLC to its channel (`HLI_CHANNEL_COMMAND.command`).
    ChannelCommand: i32, "HLI_CHANNEL_COMMAND.command" {
        /// Select the program named in `program` (and its start line).
        Select = 1,
        /// Start the selected program, or go on from a hold (feed hold or single-block stop).
        Start = 2,
        /// Decelerate on the path and end the program (it stays selected).
        Stop = 3,
        /// Decelerate on the path and hold; RESUME or START goes on from there.
        FeedHold = 4,
        /// End a feed hold.
        Resume = 5,
        /// End the program, clear the channel's and the tracking's errors; decelerates first.
        Reset = 6,
        /// Single block on (`value` 1) or off (0).
        SingleBlock = 7,
        /// Operating mode: `value` is a [`ChannelMode`].
        Mode = 8,
    }
}

hli_enum! {
    /// What a channel is doing (`HLI_CHANNEL_CONTROL_STATE.state`).
    ChannelState: i32, "HLI_CHANNEL_CONTROL_STATE.state" {
        /// No program selected.
        Idle = 0,
        /// A program is selected and ready to start (also after it ended or was stopped).
        Selected = 1,
        /// Running its program.
        Running = 2,
        /// Holding: feed hold, or a single-block stop between blocks.
        Holding = 3,
        /// Decelerating to end the program (a stop, a reset or a machine stop).
        Stopping = 4,
        /// Stopped by an error; a reset clears it.
        Error = 5,
    }
}

impl ChannelState {
    /// The state's bit in `HLI_CHANNEL_CONTROL_STATE.states_seen`.
    pub fn seen_bit(self) -> u32 {
        1 << self.raw()
    }
}

hli_enum! {
    /// A channel's operating mode.
    ChannelMode: i32, "HLI_CHANNEL_CONTROL_STATE.mode" {
        /// Programs run (START is taken).
        Automatic = 0,
        /// No program starts (START is refused); the channel's axes stand for the operator.
        Manual = 1,
    }
}

hli_enum! {
    /// Where the last command of the PLC stands (`HLI_CHANNEL_CONTROL_STATE.command_state`).
    ChannelCommandState: i32, "HLI_CHANNEL_CONTROL_STATE.command_state" {
        /// No command taken yet.
        None = 0,
        /// Taken and under way (a program loading, a stop decelerating).
        Busy = 1,
        /// Carried out.
        Done = 2,
        /// Refused or failed: `command_error` says why, nothing was changed by a refusal.
        Refused = 3,
    }
}

hli_enum! {
    /// Why the channel refused a command (`HLI_CHANNEL_CONTROL_STATE.command_error`; 0 when
    /// it did not). Ours: the manuals define no channel commands.
    ChannelCommandError: u32, "HLI_CHANNEL_CONTROL_STATE.command_error" {
        /// Not refused.
        None = 0,
        /// The command word is no command.
        UnknownCommand = 0x4A01,
        /// START without a selected program.
        NoProgram = 0x4A02,
        /// SELECT: no such program in the channel's folder.
        ProgramNotFound = 0x4A03,
        /// SELECT: the program fails its check (`message` has the first diagnostic).
        ProgramInvalid = 0x4A04,
        /// SELECT, START or MODE while a program runs.
        Running = 0x4A05,
        /// STOP, FEED_HOLD or RESUME without a running program.
        NotRunning = 0x4A06,
        /// START in ERROR: reset first.
        InError = 0x4A07,
        /// START in manual mode.
        NotAutomatic = 0x4A08,
        /// SELECT: the name is empty, not UTF-8, or no plain file name.
        BadName = 0x4A09,
        /// SELECT: the channel has no program folder configured.
        NoProgramFolder = 0x4A0A,
        /// SELECT: no block of the main program starts at `start_line`.
        StartLineNotFound = 0x4A0B,
        /// A value out of range (MODE, SINGLE_BLOCK, a negative start line).
        BadValue = 0x4A0C,
        /// The machine stops (supervision, a lost PLC): no command until it is at rest.
        MachineStop = 0x4A0D,
        /// The unit broke the protocol (a semaphore byte or payload the PLC tore).
        Protocol = 0x4A0E,
        /// A STOP or RESET ended the command before it was carried out.
        Aborted = 0x4A0F,
        /// RESET: the channel's axes could not be reset (an axis keeps its fault).
        AxisFault = 0x4A10,
        /// Another command of this channel is still under way (a SELECT loading).
        Busy = 0x4A11,
    }
}

hli_enum! {
    /// Bits of `HLI_CHANNEL_CONTROL_STATE.signals`: what an operator panel shows.
    ChannelSignal: u32, "HLI_CHANNEL_CONTROL_STATE.signals" {
        /// The program ran to its end (until the next START).
        ProgramEnd = 1,
        /// Waiting for the PLC's acknowledge of an M function.
        WaitingMAck = 2,
        /// Waiting in `#WAIT SYN` for another channel.
        WaitingSync = 4,
        /// The dynamic CS is on (ACTIVATING, ACTIVE or DEACTIVATING).
        Tracking = 8,
        /// The tracking is in ERROR.
        TrackingError = 16,
        /// A single-block stop: START runs the next block.
        SingleBlockStop = 32,
        /// The channel's axes move (path, independent axes, braking).
        Moving = 64,
        /// A dwell or `#TRACK CS ... WAIT` holds the next block back.
        Waiting = 128,
    }
}
