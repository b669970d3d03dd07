; The P3 assembler: one robot fetches a tool for each of three operations
; from a rack, uses it at the assembly station, and leaves it there.
; Action names follow the P3 generator's plans: MOVE_TO, PICK_OPn,
; PLACE_OPn, WAIT. Operations must happen in order OP1, OP2, OP3.
(define (domain p3_assembler)
  (:requirements :strips :typing :durative-actions)
  (:types agent location tool)
  (:constants assembly_station - location)
  (:predicates
    (at ?a - agent ?l - location)
    (tool_at ?t - tool ?l - location)
    (holding ?a - agent ?t - tool)
    (hand_free ?a - agent)
    (op1_done) (op2_done) (op3_done))

  (:durative-action MOVE_TO
    :parameters (?a - agent ?from - location ?to - location)
    :duration (= ?duration 2)
    :condition (at start (at ?a ?from))
    :effect (and (at start (not (at ?a ?from))) (at end (at ?a ?to))))

  (:durative-action PICK_OP1
    :parameters (?a - agent ?t - tool ?l - location)
    :duration (= ?duration 3)
    :condition (and (at start (at ?a ?l)) (at start (tool_at ?t ?l))
                    (at start (hand_free ?a)) (over all (at ?a ?l)))
    :effect (and (at start (not (hand_free ?a)))
                 (at end (not (tool_at ?t ?l))) (at end (holding ?a ?t))))

  (:durative-action PICK_OP2
    :parameters (?a - agent ?t - tool ?l - location)
    :duration (= ?duration 3)
    :condition (and (at start (op1_done)) (at start (at ?a ?l)) (at start (tool_at ?t ?l))
                    (at start (hand_free ?a)) (over all (at ?a ?l)))
    :effect (and (at start (not (hand_free ?a)))
                 (at end (not (tool_at ?t ?l))) (at end (holding ?a ?t))))

  (:durative-action PICK_OP3
    :parameters (?a - agent ?t - tool ?l - location)
    :duration (= ?duration 3)
    :condition (and (at start (op2_done)) (at start (at ?a ?l)) (at start (tool_at ?t ?l))
                    (at start (hand_free ?a)) (over all (at ?a ?l)))
    :effect (and (at start (not (hand_free ?a)))
                 (at end (not (tool_at ?t ?l))) (at end (holding ?a ?t))))

  (:durative-action PLACE_OP1
    :parameters (?a - agent ?t - tool)
    :duration (= ?duration 3)
    :condition (and (at start (holding ?a ?t)) (over all (at ?a assembly_station)))
    :effect (and (at end (not (holding ?a ?t))) (at end (hand_free ?a))
                 (at end (tool_at ?t assembly_station)) (at end (op1_done))))

  (:durative-action PLACE_OP2
    :parameters (?a - agent ?t - tool)
    :duration (= ?duration 3)
    :condition (and (at start (holding ?a ?t)) (over all (at ?a assembly_station)))
    :effect (and (at end (not (holding ?a ?t))) (at end (hand_free ?a))
                 (at end (tool_at ?t assembly_station)) (at end (op2_done))))

  (:durative-action PLACE_OP3
    :parameters (?a - agent ?t - tool)
    :duration (= ?duration 3)
    :condition (and (at start (holding ?a ?t)) (over all (at ?a assembly_station)))
    :effect (and (at end (not (holding ?a ?t))) (at end (hand_free ?a))
                 (at end (tool_at ?t assembly_station)) (at end (op3_done))))

  (:durative-action WAIT
    :parameters (?a - agent)
    :duration (= ?duration 1)
    :condition (over all (hand_free ?a))
    :effect (and))
)
