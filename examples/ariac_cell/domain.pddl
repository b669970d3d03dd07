; The ARIAC 2023 workcell as `btc trial` simulates it: two robots (the floor
; robot on its rail, the ceiling robot on its gantry), eight bins, the
; conveyor belt, two tray tables with tool changers, four AGVs that travel
; between their kitting station, two assembly stations and the warehouse,
; four assembly stations with an insert each, and a part disposal bin.
; Parts are typed by kind (battery, pump, regulator, sensor); their colour
; is the cell's to know (it names them). `cell.toml` maps trial concepts to
; the objects and facts of this domain.
(define (domain ariac_cell)
  (:requirements :strips :typing :negative-preconditions)
  (:types
    robot place agv tray gripper slot - object
    part - object
    battery pump regulator sensor - part)
  (:constants parts_gripper trays_gripper - gripper)
  (:predicates
    ; robots
    (is_enabled ?r - robot)
    (robot_at ?r - robot ?l - place)
    (reaches ?r - robot ?l - place)
    (hand_empty ?r - robot)
    (holding ?r - robot ?p - part)
    (holding_tray ?r - robot ?t - tray)
    (gripper_is ?r - robot ?g - gripper)
    ; places
    (bin ?l - place)
    (tool_changer ?l - place)
    (disposal ?l - place)
    (station ?l - place)
    ; parts
    (part_at ?p - part ?l - place)
    (flipped ?p - part)
    (in_kit ?p - part ?a - agv ?q - slot)
    (kit_slot_free ?a - agv ?q - slot)
    (installed ?p - part ?s - place)
    (insert_free ?s - place ?k - slot)
    (fits ?p - part ?k - slot)
    (discarded ?p - part)
    ; trays and AGVs
    (tray_at ?t - tray ?l - place)
    (tray_on ?t - tray ?a - agv)
    (no_tray ?a - agv)
    (agv_at ?a - agv ?l - place)
    (agv_goes ?a - agv ?l - place))

  (:action move
    :parameters (?r - robot ?from - place ?to - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?from) (reaches ?r ?to))
    :effect (and (not (robot_at ?r ?from)) (robot_at ?r ?to)))

  ; A part from a bin or the conveyor.
  (:action pick
    :parameters (?r - robot ?p - part ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (part_at ?p ?l)
      (hand_empty ?r) (gripper_is ?r parts_gripper))
    :effect (and (not (part_at ?p ?l)) (not (hand_empty ?r)) (holding ?r ?p)))

  ; A part from an AGV, wherever the AGV is.
  (:action pick_from_agv
    :parameters (?r - robot ?p - part ?a - agv ?q - slot ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (agv_at ?a ?l)
      (in_kit ?p ?a ?q) (hand_empty ?r) (gripper_is ?r parts_gripper))
    :effect (and (not (in_kit ?p ?a ?q)) (kit_slot_free ?a ?q)
      (not (hand_empty ?r)) (holding ?r ?p)))

  ; Turning a flipped part over (the robot regrasps it from the other side).
  (:action flip
    :parameters (?r - robot ?p - part)
    :precondition (and (is_enabled ?r) (holding ?r ?p) (flipped ?p))
    :effect (not (flipped ?p)))

  (:action place_in_kit
    :parameters (?r - robot ?p - part ?a - agv ?q - slot ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (agv_at ?a ?l)
      (holding ?r ?p) (kit_slot_free ?a ?q))
    :effect (and (in_kit ?p ?a ?q) (not (kit_slot_free ?a ?q))
      (not (holding ?r ?p)) (hand_empty ?r)))

  ; Putting a held part down in a bin (to free the gripper).
  (:action put_down
    :parameters (?r - robot ?p - part ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (bin ?l) (holding ?r ?p))
    :effect (and (part_at ?p ?l) (not (holding ?r ?p)) (hand_empty ?r)))

  (:action discard
    :parameters (?r - robot ?p - part ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (disposal ?l) (holding ?r ?p))
    :effect (and (discarded ?p) (not (holding ?r ?p)) (hand_empty ?r)))

  (:action assemble
    :parameters (?r - robot ?p - part ?s - place ?k - slot)
    :precondition (and (is_enabled ?r) (robot_at ?r ?s) (station ?s)
      (holding ?r ?p) (fits ?p ?k) (insert_free ?s ?k))
    :effect (and (installed ?p ?s) (not (insert_free ?s ?k))
      (not (holding ?r ?p)) (hand_empty ?r)))

  (:action change_gripper
    :parameters (?r - robot ?from - gripper ?to - gripper ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (tool_changer ?l)
      (gripper_is ?r ?from) (hand_empty ?r))
    :effect (and (not (gripper_is ?r ?from)) (gripper_is ?r ?to)))

  (:action pick_tray
    :parameters (?r - robot ?t - tray ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (tray_at ?t ?l)
      (hand_empty ?r) (gripper_is ?r trays_gripper))
    :effect (and (not (tray_at ?t ?l)) (not (hand_empty ?r)) (holding_tray ?r ?t)))

  (:action place_tray
    :parameters (?r - robot ?t - tray ?a - agv ?l - place)
    :precondition (and (is_enabled ?r) (robot_at ?r ?l) (agv_at ?a ?l)
      (holding_tray ?r ?t) (no_tray ?a))
    :effect (and (tray_on ?t ?a) (not (no_tray ?a))
      (not (holding_tray ?r ?t)) (hand_empty ?r)))

  ; AGVs move on their own (a service call of the competitor's system).
  (:action move_agv
    :parameters (?a - agv ?from - place ?to - place)
    :precondition (and (agv_at ?a ?from) (agv_goes ?a ?to))
    :effect (and (not (agv_at ?a ?from)) (agv_at ?a ?to)))
)
