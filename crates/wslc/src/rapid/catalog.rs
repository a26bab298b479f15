//! The catalogue of RAPID's built-ins: every instruction, function, data type and
//! predefined data of RobotWare that the front-end knows by name, grouped by the part of
//! RobotWare they belong to (the base system, or an option such as Socket Messaging).
//!
//! The table of what vworks runs is `lower/table.rs` (and the types of `lower/data.rs`);
//! this catalogue is what lets every *other* real built-in be a clear E0300 that names the
//! construct and its option — never "unknown … declare it with PROC". A name the program
//! declares itself is the program's (a user `PROC SocketSend` hides the built-in), so the
//! catalogue is read only for names the task does not declare.
//!
//! The names come from ABB's *Technical reference manual — RAPID Instructions, Functions
//! and Data types* (RobotWare 6) and the manuals of the options named, as recalled here:
//! the library this project is built with holds neither, so a built-in missing from the
//! catalogue is "unknown" until added. docs/rapid.md lists every group under "Not run"
//! (a test checks it).

/// What a catalogued name is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Instruction,
    Function,
    DataType,
    Data,
}

impl Kind {
    /// How a message names the kind: "the instruction".
    pub(crate) fn noun(self) -> &'static str {
        match self {
            Kind::Instruction => "the instruction",
            Kind::Function => "the function",
            Kind::DataType => "the data type",
            Kind::Data => "the predefined data",
        }
    }
}

/// A part of RobotWare and the built-ins of it that vworks does not run.
pub(crate) struct Group {
    /// The part of RobotWare, as ABB names it ("Socket Messaging").
    pub(crate) option: &'static str,
    /// Out of scope (what a simulated cell has no counterpart for), or not run yet.
    pub(crate) out_of_scope: bool,
    /// Why, and what to do instead: the diagnostic's help.
    pub(crate) help: &'static str,
    pub(crate) instructions: &'static [&'static str],
    pub(crate) functions: &'static [&'static str],
    pub(crate) types: &'static [&'static str],
    pub(crate) data: &'static [&'static str],
}

/// A catalogued built-in: its name as RAPID writes it, its kind and group.
pub(crate) struct Entry {
    pub(crate) name: &'static str,
    pub(crate) kind: Kind,
    pub(crate) group: &'static Group,
}

/// The entry of `name` (any case) among `kinds`, if RobotWare has such a built-in that
/// vworks does not run.
pub(crate) fn find(name: &str, kinds: &[Kind]) -> Option<Entry> {
    GROUPS.iter().find_map(|g| {
        [
            (Kind::Instruction, g.instructions),
            (Kind::Function, g.functions),
            (Kind::DataType, g.types),
            (Kind::Data, g.data),
        ]
        .into_iter()
        .filter(|(k, _)| kinds.contains(k))
        .find_map(|(kind, names)| {
            names
                .iter()
                .find(|n| n.eq_ignore_ascii_case(name))
                .map(|&n| Entry {
                    name: n,
                    kind,
                    group: g,
                })
        })
    })
}

impl Entry {
    /// The diagnostic's message: "`SocketCreate` is an instruction of RobotWare's Socket
    /// Messaging, which vworks does not simulate".
    pub(crate) fn message(&self) -> String {
        let noun = self.kind.noun().trim_start_matches("the ");
        if self.group.out_of_scope {
            format!(
                "`{}` is {} {noun} of RobotWare's {}, which vworks does not simulate",
                self.name,
                article(noun),
                self.group.option
            )
        } else {
            format!(
                "`{}` is {} {noun} of RobotWare's {} that vworks does not run yet",
                self.name,
                article(noun),
                self.group.option
            )
        }
    }
}

fn article(noun: &str) -> &'static str {
    if noun.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    }
}

const NOT_YET: &str = "write what it does with what vworks runs, or leave it out";

/// Every group, the base system's first.
#[rustfmt::skip]
pub(crate) const GROUPS: &[Group] = &[
    Group {
        option: "base system",
        out_of_scope: false,
        help: NOT_YET,
        instructions: &[
            "AccSet", "ActUnit", "AliasIO", "AliasIOReset", "BitClear", "BitSet",             "CallByVar", "CirPathMode", "Clear", "ClearPath",             "DeactUnit", "EOffsOff", "EOffsOn", "EOffsSet", "ErrLog", "ErrRaise", "ExitCycle",
            "GetDataVal", "GetSysData", "GetTrapData", "IError", "IPers", "ISignalAI",
            "ISignalAO", "IVarValue", "InvertDO", "IOActivate", "IODeactivate", "IODisable",
            "IOEnable", "MechUnitLoad", "MotionSup", "MoveCAO", "MoveCDO", "MoveCGO",
            "MoveCSync", "MoveExtJ", "MoveJAO", "MoveJDO", "MoveJGO", "MoveJSync", "MoveLAO",
            "MoveLDO", "MoveLGO", "MoveLSync", "PathAccLim", "PDispOff", "PDispOn", "PDispSet",
            "RaiseToUser", "ReadErrData", "RestoPath", "SearchC", "SearchExtJ", "SearchJ",
            "SearchL", "SetAllDataVal", "SetAO", "SetDataSearch", "SetDataVal", "SetSysData",
            "SkipWarn", "SpeedLimAxis", "SpeedLimCheckPoint", "SpeedRefresh", "SpyStart",
            "SpyStop", "StartMove", "StartMoveRetry", "StepBwdPath", "StopMove",
            "StopMoveReset", "StorePath", "SystemStopAction", "TestSignDefine", "TestSignReset",
            "TPReadDnum", "TPReadFK", "TPReadNum", "TPShow", "TriggC", "TriggCheckIO",
            "TriggDataCopy", "TriggDataReset", "TriggEquip", "TriggInt", "TriggIO", "TriggJ",
            "TriggJIOs", "TriggL", "TriggLIOs", "TriggRampAO", "TriggSpeed", "TriggStopProc",
            "TryInt", "TuneReset", "TuneServo", "UIMsgBox", "UIShow", "VelSet", "WaitAI",
            "WaitAO", "WaitTestAndSet", "WarmStart", "HollowWristReset",
            "SetupCyclicBrakeCheck", "ProcerrRecovery", "CapC", "CapL", "ContactL", "SoftAct",
            "SoftDeact", "DitherAct", "DitherDeact", "TextTabInstall",
        ],
        functions: &[
            "AOutput", "ArgName", "BitAnd", "BitCheck", "BitLSh", "BitNeg", "BitOr", "BitRSh",
            "BitXOr", "ByteToStr", "CalcJointT", "CalcRobT", "CalcRotAxFrameZ",
            "CalcRotAxisFrame", "CDate", "CSpeedOverride", "CTime", "CTool", "CWObj",
            "DecToHex", "DefAccFrame", "DefDFrame", "DefFrame", "Distance", "DnumToNum",
            "DnumToStr", "DotProd", "EulerZYX", "EventType", "ExecHandler", "ExecLevel", "Exp",
            "GetMecUnitName", "GetMotorTorque", "GetNextMechUnit", "GetServiceInfo",
            "GetSignalOrigin", "GetSysInfo", "GetTaskName", "GetTime", "GInputDnum",
            "GOutputDnum", "HexToDec", "IsMechUnitActive", "IsPers", "IsStopMoveAct",
            "IsStopStateEvent", "IsSysId", "IsVar", "MaxRobSpeed", "MirPos", "NonMotionMode",
            "NOrient", "NumToDnum", "OpMode", "PathLevel", "PFRestart", "PoseVect", "Pow",
            "PowDnum", "PPMovedInManMode", "ReadMotor", "RemainingRetries",
            "RobName", "RunMode", "StrDigCalc", "StrDigCmp",             "StrOrder", "StrToByte",             "TaskRunMec", "TaskRunRob", "TasksInSync", "TestAndSet", "TestSignRead", "TextGet",
            "TextTabFreeToUse", "TextTabGet", "Type", "UIAlphaEntry", "UIClientExist",
            "UIDnumEntry", "UIDnumTune", "UIListView", "UIMessageBox", "UINumEntry",
            "UINumTune", "ValidIO", "VectMagn", "IOUnitState", "ParIdPosValid", "ParIdRobValid",
            "MotionPlannerNo", "GetModalPayLoadMode",
        ],
        types: &[
            "aiotrigg", "btnres", "busstate", "buttondata", "cfgdomain", "corrdescr",
            "datapos", "dionum", "errdomain", "errstr", "errtype", "event_type",
            "exec_level", "handler_type", "icondata", "iounit_state", "listitem", "loadidnum",
            "mecunit", "motsetdata", "opcalc", "opnum", "paridnum", "paridvalidnum",
            "pathrecid", "progdisp", "restartdata", "sensor", "sensorstate",
            "signalai", "signalao", "signaldi", "signaldo", "signalgi", "signalgo",
            "stoppointdata", "stringdig", "symnum", "system_data", "taskid",
            "testsignal", "tpnum", "trapdata", "triggdata", "triggios", "triggiosdnum",
            "triggstrgo", "tunetype", "uishownum", "byte",
        ],
        data: &[
            "edge", "INTNO", "stEmpty", "diskhome",
            "disktemp", "ramdisk", "usbdisk1", "resOK", "resCancel", "resYes", "resNo",
            "resAbort", "resRetry", "resIgnore", "resUnkwn", "btnNone", "btnOK",
            "btnAbrtRtryIgn", "btnOKCancel", "btnRetryCancel", "btnYesNo", "btnYesNoCancel",
            "iconNone", "iconInfo", "iconWarning", "iconError",                                                                                                         ],
    },
    Group {
        option: "Socket Messaging",
        out_of_scope: true,
        help: "Socket Messaging talks to other computers over TCP/IP, which a simulated cell does not have: remove the calls, or exchange the data over I/O signals the workcell wires",
        instructions: &[
            "SocketAccept", "SocketBind", "SocketClose", "SocketConnect", "SocketCreate",
            "SocketListen", "SocketReceive", "SocketReceiveFrom", "SocketSend", "SocketSendTo",
        ],
        functions: &["SocketGetStatus", "SocketPeek"],
        types: &["socketdev", "socketstatus"],
        data: &[
            "SOCKET_CREATED", "SOCKET_CONNECTED", "SOCKET_BOUND", "SOCKET_LISTENING",
            "SOCKET_CLOSED", "ERR_SOCK_CLOSED", "ERR_SOCK_TIMEOUT", "ERR_SOCK_ADDR_INUSE",
            "ERR_SOCK_NET_UNREACH",
        ],
    },
    Group {
        option: "raw data (rawbytes) handling",
        out_of_scope: true,
        help: "rawbytes pack data for sockets, serial channels and fieldbus messages, which a simulated cell does not have: remove the calls",
        instructions: &[
            "ClearRawBytes", "CopyRawBytes", "PackDNHeader", "PackRawBytes", "ReadRawBytes",
            "UnpackRawBytes", "WriteRawBytes",
        ],
        functions: &["RawBytesLen"],
        types: &["rawbytes"],
        data: &[],
    },
    Group {
        option: "file and serial channel handling",
        out_of_scope: true,
        help: "files and serial channels are the controller's disks and ports, which a simulated cell does not have: remove the calls, or give the data as CONST data in the module",
        instructions: &[
            "Open", "Close", "Rewind", "Write", "WriteAnyBin", "WriteBin", "WriteStrBin",
            "ReadAnyBin", "ClearIOBuff", "MakeDir", "RemoveDir", "RemoveFile", "RenameFile",
            "CopyFile", "OpenDir", "CloseDir", "ReadBlock", "WriteBlock", "ReadCfgData",
            "WriteCfgData", "SaveCfgData", "ReadVar", "WriteVar",
        ],
        functions: &[
            "ReadBin", "ReadDir", "ReadNum", "ReadStr", "ReadStrBin", "IsFile", "FileSize",
            "FSSize",
        ],
        types: &["iodev", "dir"],
        data: &[
            "ERR_FILEOPEN", "ERR_FILEACC", "ERR_FILEEXIST", "ERR_FILNOTFND", "ERR_EOF",
        ],
    },
    Group {
        option: "program loading",
        out_of_scope: true,
        help: "a simulated task's modules are given in the workcell (`program = [\"main.mod\", \"tools.mod\"]`) and loaded before the run: list the module there and remove the call",
        instructions: &[
            "Load", "UnLoad", "StartLoad", "WaitLoad", "CancelLoad", "CheckProgRef", "Save",
            "EraseModule",
        ],
        functions: &["ModExist", "ModTime", "ProgMemFree", "GetNextSym"],
        types: &["loadsession"],
        data: &[
            "ERR_LOADED", "ERR_LOADNO_INUSE", "ERR_LOADNO_NOUSE", "ERR_MODULE",
        ],
    },
    Group {
        option: "Externally Guided Motion (EGM)",
        out_of_scope: true,
        help: "EGM moves the robot by a sensor or a computer outside the controller, which a simulated cell does not have: program the motion with MoveL/MoveJ",
        instructions: &[
            "EGMActJoint", "EGMActMove", "EGMActPose", "EGMGetId", "EGMMoveC", "EGMMoveL",
            "EGMReset", "EGMRunJoint", "EGMRunPose", "EGMSetupAI", "EGMSetupAO", "EGMSetupGI",
            "EGMSetupLTAPP", "EGMSetupUC", "EGMStop", "EGMStreamStart", "EGMStreamStop",
        ],
        functions: &["EGMGetState"],
        types: &[
            "egmident", "egmstate", "egmstopmode", "egmframetype", "egm_minmax", "egmsetuptype",
        ],
        data: &[],
    },
    Group {
        option: "Arc option",
        out_of_scope: true,
        help: "arc welding's process (the welder, the seam tracking, the weave) is not simulated: program the path with MoveL/MoveC at the weld speed",
        instructions: &[
            "ArcC", "ArcC1", "ArcC2", "ArcCEnd", "ArcCStart", "ArcKill", "ArcL", "ArcL1",
            "ArcL2", "ArcLEnd", "ArcLStart", "ArcMoveExtJ", "ArcRefresh", "ArcRepL",
        ],
        functions: &[],
        types: &["seamdata", "welddata", "weavedata", "trackdata", "arcdata"],
        data: &[],
    },
    Group {
        option: "Spot and Servo Gun options",
        out_of_scope: true,
        help: "spot welding's process (the gun, its force and tips) is not simulated: program the approach with MoveL/MoveJ and the weld time with WaitTime",
        instructions: &[
            "SpotL", "SpotJ", "SpotML", "SpotMJ", "SetForce", "CalibL", "CalibJ", "IndGunMove",
            "IndGunMoveReset", "STCalib", "STClose", "STOpen", "STTune", "STTuneReset",
        ],
        functions: &[
            "STCalcForce", "STCalcTorque", "STIsCalib", "STIsClosed", "STIsIndGun", "STIsOpen",
        ],
        types: &["spotdata", "gundata", "forcedata", "simdata", "smeqdata"],
        data: &[],
    },
    Group {
        option: "Dispense option",
        out_of_scope: true,
        help: "dispensing's process (the beads and the equipment) is not simulated: program the path with MoveL/MoveC",
        instructions: &["DispL", "DispC"],
        functions: &[],
        types: &["beaddata", "equipdata"],
        data: &[],
    },
    Group {
        option: "RAPID Message Queue (RMQ)",
        out_of_scope: true,
        help: "RAPID Message Queues carry messages between tasks and to clients outside the controller: exchange the data through PERS data or I/O signals the workcell wires, which vworks runs",
        instructions: &[
            "IRMQMessage", "RMQEmptyQueue", "RMQFindSlot", "RMQGetMessage", "RMQGetMsgData",
            "RMQGetMsgHeader", "RMQReadWait", "RMQSendMessage", "RMQSendWait",
        ],
        functions: &["RMQGetSlotName"],
        types: &["rmqslot", "rmqheader", "rmqmessage"],
        data: &[],
    },
    Group {
        option: "MultiMove Coordinated option",
        out_of_scope: true,
        help: "coordinated (synchronised) motion of several tasks is not simulated; WaitSyncTask, which vworks runs, meets the tasks at a point without coordinating their paths",
        instructions: &[
            "SyncMoveOn", "SyncMoveOff", "SyncMoveResume", "SyncMoveSuspend", "SyncMoveUndo",
        ],
        functions: &["IsSyncMoveOn"],
        types: &["identno"],
        data: &[],
    },
    Group {
        option: "Force Control option",
        out_of_scope: true,
        help: "force control reacts to contact forces measured by a sensor, which a simulated cell does not have: program the motion with MoveL",
        instructions: &[
            "FCAct", "FCDeact", "FCCalib", "FCCondForce", "FCCondOrient", "FCCondPos",
            "FCCondReoSpeed", "FCCondTCPSpeed", "FCCondTorque", "FCCondWaitWhile", "FCDamping",
            "FCLoadID", "FCPress1LStart", "FCPressC", "FCPressEnd", "FCPressL", "FCRefCircle",
            "FCRefForce", "FCRefLine", "FCRefMoveFrame", "FCRefRot", "FCRefSpiral",
            "FCRefSprForceCart", "FCRefStart", "FCRefStop", "FCRefTorque", "FCResetDampingTune",
            "FCSpdChgAct", "FCSpdChgDeact", "FCSupvForce", "FCSupvOrient", "FCSupvPos",
            "FCSupvReoSpeed", "FCSupvSpeed", "FCSupvTCPSpeed",
        ],
        functions: &["FCGetForce", "FCGetProcessData", "FCIsForceMode"],
        types: &[
            "fcboxvol", "fccondstatus", "fccylindervol", "fcdamping", "fcframe",
            "fcprocessdata", "fcspdchgtunetype", "fcspherevol", "fcxyznum",
        ],
        data: &[],
    },
    Group {
        option: "Conveyor Tracking option",
        out_of_scope: true,
        help: "work objects on a moving conveyor are not simulated: give the work object a fixed frame",
        instructions: &["WaitWObj", "DropWObj"],
        functions: &[],
        types: &[],
        data: &[],
    },
    Group {
        option: "World Zones option",
        out_of_scope: true,
        help: "world zones supervise the TCP against boxes, cylinders and spheres in the controller; in vworks, give the workcell the shapes and it checks collisions at every cycle (docs/engine.md)",
        instructions: &[
            "WZBoxDef", "WZCylDef", "WZDisable", "WZDOSet", "WZEnable", "WZFree",
            "WZHomeJointDef", "WZLimJointDef", "WZLimSup", "WZSphDef",
        ],
        functions: &[],
        types: &["shapedata", "wzstationary", "wztemporary"],
        data: &[],
    },
    Group {
        option: "Independent Axes option",
        out_of_scope: true,
        help: "an axis moved independently of the robot's program (an endless turntable) is not simulated",
        instructions: &["IndAMove", "IndCMove", "IndDMove", "IndReset", "IndRMove"],
        functions: &["IndInpos", "IndSpeed"],
        types: &[],
        data: &[],
    },
    Group {
        option: "Path Offset and sensor interface options",
        out_of_scope: true,
        help: "path corrections from a sensor (seam tracking, laser, camera) are not simulated: the robot moves its programmed path",
        instructions: &[
            "CorrClear", "CorrCon", "CorrDiscon", "CorrWrite", "SenDevice", "CSSAct",
            "CSSDeact", "CSSForceOffsetAct", "CSSForceOffsetDeact",
        ],
        functions: &["CorrRead"],
        types: &[],
        data: &[],
    },
    Group {
        option: "Path Recovery option",
        out_of_scope: false,
        help: NOT_YET,
        instructions: &[
            "PathRecMoveBwd", "PathRecMoveFwd", "PathRecStart", "PathRecStop",
        ],
        functions: &["PathRecValidBwd", "PathRecValidFwd"],
        types: &[],
        data: &[],
    },
    Group {
        option: "tool and work object calibration",
        out_of_scope: true,
        help: "calibrating a tool or a work object measures the real one by touching points, which a simulated cell does not need: give the tooldata or wobjdata its value",
        instructions: &[
            "MToolRotCalib", "MToolTCPCalib", "SToolRotCalib", "SToolTCPCalib",
        ],
        functions: &[],
        types: &[],
        data: &[],
    },
];

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::rapid::lower::table::{FUNCTIONS, INSTRUCTIONS, find as find_row};

    const DOC: &str = include_str!("../../../../docs/rapid.md");

    /// Every name once in the catalogue (but a type that is also another group's), and
    /// none the front-end runs.
    #[test]
    fn each_built_in_is_catalogued_once_and_none_that_vworks_runs() {
        let mut seen: Vec<(String, Kind)> = Vec::new();
        for g in GROUPS {
            for (kind, names) in [
                (Kind::Instruction, g.instructions),
                (Kind::Function, g.functions),
                (Kind::DataType, g.types),
                (Kind::Data, g.data),
            ] {
                for n in names {
                    let key = n.to_ascii_lowercase();
                    if kind != Kind::DataType {
                        assert!(
                            !seen.contains(&(key.clone(), kind)),
                            "`{n}` twice in the catalogue"
                        );
                    }
                    seen.push((key, kind));
                    if kind == Kind::Instruction {
                        assert!(find_row(INSTRUCTIONS, n).is_none(), "vworks runs `{n}`");
                    }
                    if kind == Kind::Function {
                        assert!(find_row(FUNCTIONS, n).is_none(), "vworks runs `{n}`");
                    }
                }
            }
        }
        assert!(seen.len() > 500, "{}", seen.len());
    }

    /// docs/rapid.md's "Not run" section names every group and every instruction and
    /// function of it, so the reference and the catalogue say the same.
    #[test]
    fn the_rapid_reference_lists_every_catalogued_built_in() {
        let from = DOC
            .find("## Not run")
            .expect("docs/rapid.md has `## Not run`");
        let section = &DOC[from..];
        for g in GROUPS {
            assert!(section.contains(g.option), "docs/rapid.md: {}", g.option);
            for n in g.instructions.iter().chain(g.functions).chain(g.types) {
                assert!(
                    section.contains(&format!("`{n}`")),
                    "docs/rapid.md's `## Not run` does not name `{n}` ({})",
                    g.option
                );
            }
        }
    }

    #[test]
    fn a_lookup_ignores_case_and_keeps_to_the_kinds_asked() {
        let e = find("socketcreate", &[Kind::Instruction]).unwrap();
        assert_eq!(e.name, "SocketCreate");
        assert_eq!(
            e.message(),
            "`SocketCreate` is an instruction of RobotWare's Socket Messaging, which vworks does not simulate"
        );
        assert!(find("SocketCreate", &[Kind::Function]).is_none());
        let e = find("STRORDER", &[Kind::Function]).unwrap();
        assert!(
            e.message()
                .ends_with("base system that vworks does not run yet")
        );
        assert!(find("MoveL", &[Kind::Instruction]).is_none());
    }
}
