; A kitting cell in the spirit of the NIST executor (Kootbally): a robot
; changes end effectors, takes parts from parts trays and puts them into a
; kit. The rules turn each step into canonical robot commands.
(define (domain kitting)
  (:requirements :strips :typing :negative-preconditions)
  (:types robot endeffector holder part partstray kit)
  (:predicates
    (robot-empty ?r - robot)
    (robot-has-eff ?r - robot ?e - endeffector)
    (eff-in-holder ?e - endeffector ?h - holder)
    (eff-fits ?e - endeffector ?p - part)
    (part-in-tray ?p - part ?t - partstray)
    (robot-holds ?r - robot ?p - part)
    (part-in-kit ?p - part ?k - kit))
  (:action attach-eff
    :parameters (?r - robot ?e - endeffector ?h - holder)
    :precondition (and (eff-in-holder ?e ?h) (not (robot-has-eff ?r ?e)))
    :effect (and (robot-has-eff ?r ?e) (not (eff-in-holder ?e ?h))))
  (:action remove-eff
    :parameters (?r - robot ?e - endeffector ?h - holder)
    :precondition (and (robot-has-eff ?r ?e) (robot-empty ?r))
    :effect (and (not (robot-has-eff ?r ?e)) (eff-in-holder ?e ?h)))
  (:action take-part
    :parameters (?r - robot ?p - part ?t - partstray ?e - endeffector)
    :precondition (and (part-in-tray ?p ?t) (robot-empty ?r) (robot-has-eff ?r ?e) (eff-fits ?e ?p))
    :effect (and (robot-holds ?r ?p) (not (robot-empty ?r)) (not (part-in-tray ?p ?t))))
  (:action put-part
    :parameters (?r - robot ?p - part ?k - kit)
    :precondition (robot-holds ?r ?p)
    :effect (and (part-in-kit ?p ?k) (robot-empty ?r) (not (robot-holds ?r ?p)))))
