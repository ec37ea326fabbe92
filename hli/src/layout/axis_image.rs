//! The process image of an NC axis towards its encoder and drive (seed 004), in the order the
//! specification lists the signals, with natural alignment and explicit padding.
//!
//! The specification names the signals but not a byte layout; this is ours: increments and
//! data words are DINT, status and control words are one byte each. A 16-bit encoder uses the
//! low 16 bits of `nInData1` (the axis configuration says which width counts).

use crate::hli_struct;

hli_struct! {
    /// Encoder inputs: what the encoder (or the drive's position feedback) delivers to the NC.
    ///
    /// ST path: `gpAx[i]^enc_in`.
    #[st = "NC_ENCODER_PI_IN", size = 40]
    pub struct NcEncoderIn {
        /// Actual position in increments; the NC counts its overflows.
        pub nInData1: i32 => [0, Io],
        /// Optional latched actual position in increments (touch probe).
        pub nInData2: i32 => [4, Io],
        /// Optional status (device dependent).
        pub nStatus1: u8 => [8, Io],
        /// Optional further status (device dependent).
        pub nStatus2: u8 => [9, Io],
        /// Reserved.
        pub nStatus3: u8 => [10, Io],
        /// Field-bus I/O state: 0 data valid, 1 data invalid.
        pub nStatus4: u8 => [11, Io],
        /// Touch probe 1, positive edge position.
        pub nInData3: i32 => [12, Io],
        /// Touch probe 1, negative edge position.
        pub nInData4: i32 => [16, Io],
        /// Touch probe 2, positive edge position.
        pub nInData5: i32 => [20, Io],
        /// Touch probe 2, negative edge position.
        pub nInData6: i32 => [24, Io],
        /// Probe 1 positive edge latched (or probe status low byte).
        pub nStatus5: u8 => [28, Io],
        /// Probe 1 negative edge latched (or probe status high byte).
        pub nStatus6: u8 => [29, Io],
        /// Probe 2 positive edge latched.
        pub nStatus7: u8 => [30, Io],
        /// Probe 2 negative edge latched.
        pub nStatus8: u8 => [31, Io],
        /// Optional distributed-clock input time, for dead-time compensation.
        pub nDcInputTime: i32 => [32, Io],
        /// Padding.
        pub fill_up_1: i32 => [36, Io],
    }
}

hli_struct! {
    /// Encoder outputs: what the NC sends to the encoder.
    ///
    /// ST path: `gpAx[i]^enc_out`.
    #[st = "NC_ENCODER_PI_OUT", size = 32]
    pub struct NcEncoderOut {
        /// Mirror of the encoder input `nInData1`, copied by the NC every tick.
        pub nOutData1: i32 => [0, Cnc],
        /// The value (increments) the counter is set to while a set-counter request is in
        /// `nCtrl2` (0x01), else 0. The specification reserves this word; the use is ours
        /// (docs/axes.md, "The encoder's register").
        pub nOutData2: i32 => [4, Cnc],
        /// Optional control (latch, encoder reset, register access).
        pub nCtrl1: u8 => [8, Cnc],
        /// Optional further control.
        pub nCtrl2: u8 => [9, Cnc],
        /// Reserved.
        pub nCtrl3: u8 => [10, Cnc],
        /// Reserved.
        pub nCtrl4: u8 => [11, Cnc],
        /// Reserved.
        pub nOutData3: i32 => [12, Cnc],
        /// Reserved.
        pub nOutData4: i32 => [16, Cnc],
        /// Reserved.
        pub nOutData5: i32 => [20, Cnc],
        /// Reserved.
        pub nOutData6: i32 => [24, Cnc],
        /// Probe 1 enable.
        pub nCtrl5: u8 => [28, Cnc],
        /// Probe 2 enable.
        pub nCtrl6: u8 => [29, Cnc],
        /// Reserved.
        pub nCtrl7: u8 => [30, Cnc],
        /// Reserved.
        pub nCtrl8: u8 => [31, Cnc],
    }
}

hli_struct! {
    /// Drive inputs: what the drive reports to the NC.
    ///
    /// ST path: `gpAx[i]^drive_in`.
    #[st = "NC_DRIVE_PI_IN", size = 40]
    pub struct NcDriveIn {
        /// Optional following error of the drive in increments (cyclic position mode).
        pub nInData1: i32 => [0, Io],
        /// Reserved.
        pub nInData2: i32 => [4, Io],
        /// Optional drive status (fault, enabled, state machine).
        pub nStatus1: u8 => [8, Io],
        /// Optional further drive status.
        pub nStatus2: u8 => [9, Io],
        /// Reserved.
        pub nStatus3: u8 => [10, Io],
        /// Field-bus I/O state: 0 data valid, 1 data invalid.
        pub nStatus4: u8 => [11, Io],
        /// Optional actual torque/force in increments.
        pub nInData3: i32 => [12, Io],
        /// Reserved.
        pub nInData4: i32 => [16, Io],
        /// Reserved.
        pub nInData5: i32 => [20, Io],
        /// Reserved.
        pub nInData6: i32 => [24, Io],
        /// Reserved.
        pub nStatus5: u8 => [28, Io],
        /// Reserved.
        pub nStatus6: u8 => [29, Io],
        /// Reserved.
        pub nStatus7: u8 => [30, Io],
        /// Reserved.
        pub nStatus8: u8 => [31, Io],
        /// Optional distributed-clock output time, for dead-time compensation of the drive.
        pub nDcOutputTime: i32 => [32, Io],
        /// Padding.
        pub fill_up_1: i32 => [36, Io],
    }
}

hli_struct! {
    /// Drive outputs: the set-point the NC sends to the drive.
    ///
    /// ST path: `gpAx[i]^drive_out`.
    #[st = "NC_DRIVE_PI_OUT", size = 32]
    pub struct NcDriveOut {
        /// Set velocity or set position in increments; for the universal drive the signed total
        /// velocity (including the position controller's share).
        pub nOutData1: i32 => [0, Cnc],
        /// Set velocity or set position in increments; for the universal drive the magnitude of
        /// the total velocity.
        pub nOutData2: i32 => [4, Cnc],
        /// Optional control (reset, enable, state machine).
        pub nCtrl1: u8 => [8, Cnc],
        /// Direction of the set-point generator: 0x41 minus, 0x42 plus, 0x80 stop.
        pub nCtrl2: u8 => [9, Cnc],
        /// Direction of the total output (generator + position controller), same coding.
        pub nCtrl3: u8 => [10, Cnc],
        /// Reserved.
        pub nCtrl4: u8 => [11, Cnc],
        /// Set acceleration (and/or set torque) in increments, signed.
        pub nOutData3: i32 => [12, Cnc],
        /// Reserved.
        pub nOutData4: i32 => [16, Cnc],
        /// Reserved.
        pub nOutData5: i32 => [20, Cnc],
        /// Reserved.
        pub nOutData6: i32 => [24, Cnc],
        /// Reserved.
        pub nCtrl5: u8 => [28, Cnc],
        /// Reserved.
        pub nCtrl6: u8 => [29, Cnc],
        /// Reserved.
        pub nCtrl7: u8 => [30, Cnc],
        /// Reserved.
        pub nCtrl8: u8 => [31, Cnc],
    }
}
