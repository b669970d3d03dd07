//! Orders and their tasks: kitting, assembly, combined.

use super::*;

impl Reader {
    pub(super) fn orders(&mut self, node: &Node) -> Vec<Order> {
        let Some(list) = self.list(node, "`orders`") else {
            return Vec::new();
        };
        if list.is_empty() {
            self.error(
                codes::TRIAL_MISSING,
                node.range,
                "`orders` is empty: a trial needs at least one order",
            );
        }
        let mut out: Vec<Order> = Vec::new();
        for o in list {
            let Some(order) = self.order(o) else {
                continue;
            };
            if let Some(first) = out.iter().find(|x| x.id == order.id) {
                let first = first.range;
                self.twice(
                    o.range,
                    format!(
                        "order id `{}` is given twice; each order needs its own",
                        order.id
                    ),
                    first,
                    "the first order with this id",
                );
                continue;
            }
            out.push(order);
        }
        out
    }

    pub(super) fn order(&mut self, node: &Node) -> Option<Order> {
        let mut f = self.fields(node, "an order")?;
        let id = self
            .need(&mut f, "id")
            .and_then(|n| self.text(n, "an order id"))
            .map(str::to_owned);
        let what = match &id {
            Some(id) => format!("order `{id}`"),
            None => "an order".to_owned(),
        };
        let ty_node = self.need(&mut f, "type");
        let ty = ty_node
            .and_then(|n| self.choice(n, "an order type", &["kitting", "assembly", "combined"]));
        let priority = match f.get("priority") {
            Some(n) => self.boolean(n, "`priority`").unwrap_or(false),
            None => {
                self.missing(
                    node,
                    format!("{what} has no `priority` (`true` or `false`)"),
                );
                false
            }
        };
        let announcement = match self.need(&mut f, "announcement") {
            Some(n) => match self.fields(n, "`announcement`") {
                Some(mut af) => {
                    let c = self.condition(&mut af, &format!("the announcement of {what}"));
                    self.done(
                        af,
                        &[
                            "time_condition",
                            "part_place_condition",
                            "submission_condition",
                        ],
                    );
                    c
                }
                None => None,
            },
            None => None,
        };
        let tasks = ["kitting_task", "assembly_task", "combined_task"];
        let given: Vec<&str> = tasks.iter().copied().filter(|k| f.has(k)).collect();
        let task = match (ty, given.as_slice()) {
            (_, []) => {
                self.missing(node, format!("{what} has no task: give `kitting_task`, `assembly_task` or `combined_task`"));
                None
            }
            (_, [one]) => {
                let n = f.get(one).expect("present");
                if let Some(t) = ty {
                    if format!("{t}_task") != *one {
                        self.error(
                            codes::TRIAL_VALUE,
                            n.range,
                            format!("{what} is of type `{t}` but gives `{one}`"),
                        )
                        .hint = Some(format!("a `{t}` order gives `{t}_task`"));
                    }
                }
                match *one {
                    "kitting_task" => self.kitting(n),
                    "assembly_task" => self.assembly(n),
                    _ => self.combined(n),
                }
            }
            (_, [_, second, ..]) => {
                let n = f.get(second).expect("present");
                self.error(
                    codes::TRIAL_VALUE,
                    n.range,
                    format!("{what} gives more than one task; an order has exactly one"),
                );
                None
            }
        };
        self.done(
            f,
            &[
                "id",
                "type",
                "announcement",
                "priority",
                "kitting_task",
                "assembly_task",
                "combined_task",
            ],
        );
        Some(Order {
            id: id?,
            priority,
            announcement: announcement?,
            task: task?,
            range: node.range,
        })
    }

    pub(super) fn station(&mut self, node: &Node) -> Option<u8> {
        let n = self.choice(node, "an assembly station", &["as1", "as2", "as3", "as4"])?;
        numbered(n, "as", 1, 4)
    }

    pub(super) fn kitting(&mut self, node: &Node) -> Option<Task> {
        let mut f = self.fields(node, "`kitting_task`")?;
        let agv = self
            .need(&mut f, "agv_number")
            .and_then(|n| self.int(n, "an AGV number", 1, 4));
        let tray = self
            .need(&mut f, "tray_id")
            .and_then(|n| self.int(n, "a kit tray id", 0, 9));
        let dest = self.need(&mut f, "destination").and_then(|n| {
            let d = self.choice(
                n,
                "a kit destination",
                &["warehouse", "kitting", "as1", "as2", "as3", "as4"],
            )?;
            Some(match d {
                "warehouse" => Destination::Warehouse,
                "kitting" => Destination::Kitting,
                s => Destination::Station(numbered(s, "as", 1, 4)?),
            })
        });
        let mut products: Vec<KitProduct> = Vec::new();
        if let Some(list) = self
            .need(&mut f, "products")
            .and_then(|n| self.list(n, "`products`"))
        {
            if list.is_empty() {
                self.error(
                    codes::TRIAL_MISSING,
                    node.range,
                    "this kitting task has no products",
                );
            }
            products = self.parts(
                list,
                "a kitting product",
                &["quadrant"],
                |r, pf| r.quadrant(pf),
                |r, part, products: &[KitProduct]| {
                    let kind = part.kind?;
                    let quadrant =
                        r.free_quadrant(part.own, products.iter().map(|x| x.quadrant), |q| {
                            format!("quadrant {q} is asked for twice in this kit")
                        })?;
                    Some(KitProduct {
                        kind,
                        quadrant,
                        range: part.node.range,
                    })
                },
            );
        }
        self.done(f, &["agv_number", "tray_id", "destination", "products"]);
        Some(Task::Kitting {
            agv: agv? as u8,
            tray_id: tray? as u8,
            destination: dest?,
            products,
        })
    }

    pub(super) fn products(&mut self, f: &mut Fields<'_>, at: &Node) -> Vec<AssemblyProduct> {
        let Some(list) = self
            .need(f, "products")
            .and_then(|n| self.list(n, "`products`"))
        else {
            return Vec::new();
        };
        if list.is_empty() {
            self.error(codes::TRIAL_MISSING, at.range, "this task has no products");
        }
        self.parts(
            list,
            "an assembly product",
            &["assembled_pose", "assembly_direction"],
            |r, pf| {
                for key in ["assembled_pose", "assembly_direction"] {
                    if let Some(n) = pf.get(key) {
                        r.unsimulated(
                            if key == "assembled_pose" {
                                "assembled_pose"
                            } else {
                                "assembly_direction"
                            },
                            n,
                            "an assembled part is in its slot or not; btc's world has no poses",
                        );
                    }
                }
            },
            |r, part, out: &[AssemblyProduct]| {
                let kind = part.kind?;
                // An insert has one slot per part type.
                if out.iter().any(|x| x.kind.ty == kind.ty) {
                    r.error(
                        codes::TRIAL_DUPLICATE,
                        part.node.range,
                        format!(
                            "a second {}: an insert has one slot per part type",
                            kind.ty.name()
                        ),
                    );
                    return None;
                }
                Some(AssemblyProduct {
                    kind,
                    range: part.node.range,
                })
            },
        )
    }

    pub(super) fn assembly(&mut self, node: &Node) -> Option<Task> {
        let mut f = self.fields(node, "`assembly_task`")?;
        let mut agvs = Vec::new();
        if let Some(n) = self.need(&mut f, "agv_number") {
            // ARIAC's reader iterates it; a single number is a common slip.
            let items: Vec<&Node> = match n.as_seq() {
                Some(s) => s.iter().collect(),
                None => vec![n],
            };
            for a in items {
                if let Some(x) = self.int(a, "an AGV number", 1, 4) {
                    if !agvs.contains(&(x as u8)) {
                        agvs.push(x as u8);
                    }
                }
            }
        }
        let station = self.need(&mut f, "station").and_then(|n| self.station(n));
        let products = self.products(&mut f, node);
        self.done(f, &["agv_number", "station", "products"]);
        Some(Task::Assembly {
            agvs,
            station: station?,
            products,
        })
    }

    pub(super) fn combined(&mut self, node: &Node) -> Option<Task> {
        let mut f = self.fields(node, "`combined_task`")?;
        let station = self.need(&mut f, "station").and_then(|n| self.station(n));
        let products = self.products(&mut f, node);
        self.done(f, &["station", "products"]);
        Some(Task::Combined {
            station: station?,
            products,
        })
    }
}
